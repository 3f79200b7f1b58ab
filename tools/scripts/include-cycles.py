#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Circles in the include graph (make test runs it: tests/test_includes.c).

Usage: tools/scripts/include-cycles.py [--root DIR] [-v]

Reports, and exits 1 on, any circle
  (a) between the files of one folder (a module) under firmware/,
      platform/, hal/, sim/ and apps/, such as firmware/image/;
  (b) between the folders of tools/ (tools/modal, tools/dist, ...; a
      subfolder such as tools/dist/plugin counts as its folder).

The graph is built from `#include "..."` lines, resolved as the compiler
does: beside the including file, then in the include folders (every
folder named include under those above, and tools/).  Its nodes:
  - in (a), one node per file stem: foo.c and foo.h of one folder are one
    node, "foo";
  - in (b), one node per folder.
A header stands for itself and for the files that define the functions it
names (a prototype, or a call in an inline function or a macro): a file
that includes a catch-all private header depends on every file behind it,
so a circle cannot hide behind one header that declares everything.
Headers outside the folder in (a) (the public firmware/include/irdm/*.h)
are the module's face and are not followed: a circle through them is not
one between the files of the folder.

-v prints every edge with the include that makes it.
"""
import argparse
import os
import re
import sys

FILE_SCOPES = ["firmware", "platform", "hal", "sim", "apps"]
FOLDER_SCOPE = "tools"

INCLUDE_RE = re.compile(r'^[ \t]*#[ \t]*include[ \t]*"([^"]+)"', re.M)
IDENT_RE = re.compile(r"[A-Za-z_]\w*")
CALL_RE = re.compile(r"([A-Za-z_]\w*)\s*\(")


def strip_comments(text, literals=True):
    """Comments removed (lines kept); string and char literals emptied
    unless literals is False."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c if literals else text[i:j + 1])
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def strip_preprocessor(text):
    return re.sub(r"^[ \t]*#(?:[^\n]*\\\n)*[^\n]*", "", text, flags=re.M)


def defined_functions(text):
    """Names of the functions a .c file defines: (external, all)."""
    code = strip_preprocessor(strip_comments(text))
    external, every = set(), set()
    depth, start = 0, 0
    for i, c in enumerate(code):
        if c == "{":
            if depth == 0:
                head = code[start:i]
                words = IDENT_RE.findall(head)
                call = CALL_RE.search(head)
                if (call and "=" not in head and words
                        and words[0] not in ("struct", "union", "enum", "typedef")):
                    every.add(call.group(1))
                    if "static" not in words:
                        external.add(call.group(1))
            depth += 1
        elif c == "}":
            depth -= 1
            if depth == 0:
                start = i + 1
        elif c == ";" and depth == 0:
            start = i + 1
    return external, every


def called_in_bodies(text):
    """Names called inside the bodies of a header's inline functions."""
    code = strip_preprocessor(strip_comments(text))
    names, depth, start = set(), 0, 0
    for i, c in enumerate(code):
        if c == "{":
            if depth == 0:
                start = i
            depth += 1
        elif c == "}":
            depth -= 1
            if depth == 0:
                names |= set(CALL_RE.findall(code[start:i]))
    return names


def include_dirs(root):
    """The -I folders: every include folder of the scopes, then tools/."""
    found = []
    for top in FILE_SCOPES:
        for d, subdirs, _ in os.walk(os.path.join(root, top)):
            subdirs.sort()
            if os.path.basename(d) == "include":
                found.append(os.path.relpath(d, root))
                subdirs[:] = []
    return found + [FOLDER_SCOPE]


class Tree:
    def __init__(self, root):
        self.root = root
        self.include_dirs = include_dirs(root)
        self.files = {}         # relative path -> text
        for top in FILE_SCOPES + [FOLDER_SCOPE]:
            base = os.path.join(root, top)
            for d, subdirs, names in os.walk(base):
                subdirs.sort()
                for name in sorted(names):
                    if name.endswith((".c", ".h")):
                        path = os.path.relpath(os.path.join(d, name), root)
                        if path not in self.files:
                            with open(os.path.join(d, name), errors="replace") as f:
                                self.files[path] = f.read()
        self.idents = {p: set(IDENT_RE.findall(strip_comments(t)))
                       for p, t in self.files.items()}
        self.definers = {}      # function name -> .c files defining it (external)
        self.own = {}           # .c file -> every function it defines
        for path, text in self.files.items():
            if path.endswith(".c"):
                external, self.own[path] = defined_functions(text)
                for name in external:
                    self.definers.setdefault(name, set()).add(path)
        self.includes = {p: self.resolve(p) for p in self.files}

    def resolve(self, path):
        """The files path includes with "...", resolved."""
        out = []
        for inc in INCLUDE_RE.findall(strip_comments(self.files[path], literals=False)):
            for d in [os.path.dirname(path)] + self.include_dirs:
                cand = os.path.normpath(os.path.join(d, inc))
                if cand in self.files:
                    out.append(cand)
                    break
        return out

    def headers_of(self, path):
        """Every header path includes, directly or through another."""
        seen, todo = [], list(self.includes[path])
        while todo:
            h = todo.pop(0)
            if h not in seen:
                seen.append(h)
                todo.extend(self.includes[h])
        return seen

    def uses(self, path):
        """(function, header declaring it, file defining it) for every
        function of another file that path calls or takes the address of."""
        out = []
        if path.endswith(".c"):
            names = self.idents[path] - self.own[path]
            for h in self.headers_of(path):
                for name in sorted(names & self.idents[h]):
                    for c in sorted(self.definers.get(name, ())):
                        out.append((name, h, c))
                names -= self.idents[h]
        else:
            for name in sorted(called_in_bodies(self.files[path])):
                for c in sorted(self.definers.get(name, ())):
                    out.append((name, path, c))
        return out

    def edges(self, node_of):
        """Edges between nodes (node_of(path): its node or None), each with
        the first reason found for it."""
        edges = {}

        def add(a, b, why):
            if a is not None and b is not None and a != b:
                edges.setdefault(a, {}).setdefault(b, why)

        for path in self.files:
            a = node_of(path)
            if a is None:
                continue
            for inc in self.includes[path]:
                add(a, node_of(inc), "%s includes %s" % (path, inc))
            for name, h, c in self.uses(path):
                add(a, node_of(c), "%s calls %s() of %s (%s)" % (path, name, c, h))
        return edges


def cycles(edges):
    """One circle per strongly connected component of more than one node."""
    index, low, stack, on, comps = {}, {}, [], set(), []
    nodes = sorted(set(edges) | {b for a in edges for b in edges[a]})

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, {})):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in nodes:
        if v not in index:
            visit(v)
    out = []
    for comp in comps:
        out.append((comp, shortest_circle(edges, comp)))
    return out


def shortest_circle(edges, comp):
    """The shortest path from comp[0] back to itself inside comp."""
    inside = set(comp)
    start = comp[0]
    prev = {start: None}
    queue = [start]
    for v in queue:
        for w in sorted(edges.get(v, {})):
            if w == start:
                path = [v]
                while prev[path[-1]] is not None:
                    path.append(prev[path[-1]])
                path.reverse()
                return path + [start]
            if w in inside and w not in prev:
                prev[w] = v
                queue.append(w)
    return comp


def file_node(folder):
    def node_of(path):
        return os.path.basename(path) if os.path.dirname(path) == folder else None
    return node_of


def folder_node(path):
    parts = path.split(os.sep)
    if len(parts) < 3 or parts[0] != FOLDER_SCOPE:
        return None
    return parts[0] + "/" + parts[1]


def report(title, edges, verbose):
    if verbose:
        for a in sorted(edges):
            for b in sorted(edges[a]):
                print("%s: %s -> %s (%s)" % (title, a, b, edges[a][b]))
    found = cycles(edges)
    for comp, circle in found:
        print("%s: circle: %s" % (title, " -> ".join(circle)))
        for a, b in zip(circle, circle[1:]):
            print("    %s -> %s: %s" % (a, b, edges[a][b]))
        if len(comp) > len(circle) - 1:
            print("    (all of: %s)" % ", ".join(comp))
    return len(found)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                   "..", ".."))
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args()
    tree = Tree(os.path.normpath(args.root))
    n = 0
    folders = sorted({os.path.dirname(p) for p in tree.files
                      if p.split(os.sep)[0] in FILE_SCOPES and "/include/" not in "/" + p})
    for folder in folders:
        n += report(folder, tree.edges(file_node(folder)), args.verbose)
    n += report(FOLDER_SCOPE, tree.edges(folder_node), args.verbose)
    if n:
        print("include-cycles: %d circle(s)" % n)
        return 1
    tops = sorted({f.split(os.sep)[0] + "/" for f in folders})
    print("include-cycles: no circle in %d folders of %s, nor between the folders of %s/"
          % (len(folders), ", ".join(tops) or "none", FOLDER_SCOPE))
    return 0


if __name__ == "__main__":
    sys.exit(main())
