#!/usr/bin/python3
"""Draw deformed-surface frames written by `irdm-fw --frame-at S --frame-out FILE.vtk`
or `--frames-every S --frames-out DIR` (legacy VTK POLYDATA, ASCII), or by
`irdm render` (VTK XML .vtu, ASCII; a .pvd stands for all its frames): the shaded
surface coloured by displacement magnitude (mm), each contact point and the force
on the object as an arrow.  Several frames make a strip with one colour range;
--each OUTDIR draws one PNG per frame instead (OUTDIR/frame_NNNNN.png, every
--step K-th frame), all with one scale and colour range, for a film.
The displacement is exaggerated by --scale (default: so that the largest one is
a tenth of the object's size); the colours are the true magnitudes.
usage: plot-surface.py FRAME.vtk|.vtu|.pvd ... OUT.png [title] [--scale=K]
       plot-surface.py FRAME.vtu|.pvd ... --each OUTDIR [--step=K] [title] [--scale=K]"""
import os
import sys
import xml.etree.ElementTree as ET

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection


def fail(msg):
    sys.exit(f"plot-surface: {msg}")


def numbers(tok, i, n, kind=float):
    if i + n > len(tok):
        fail("file ends inside a block")
    return np.array([kind(x) for x in tok[i:i + n]]), i + n


def read_vtk(path):
    """Points, triangles, per-point displacement, and the dataset's field data."""
    with open(path) as f:
        lines = f.read().split("\n")
    if not lines[0].startswith("# vtk DataFile") or lines[2].strip() != "ASCII":
        fail(f"{path}: not a legacy ASCII VTK file")
    tok = " ".join(lines[3:]).split()
    out, field, i = {}, {}, 0
    while i < len(tok):
        key = tok[i]
        if key == "DATASET":
            i += 2
        elif key == "FIELD":
            count, i = int(tok[i + 2]), i + 3
            for _ in range(count):
                name, comps, tuples = tok[i], int(tok[i + 1]), int(tok[i + 2])
                v, i = numbers(tok, i + 4, comps * tuples)
                field[name] = v.reshape(tuples, comps)
        elif key == "POINTS":
            n = int(tok[i + 1])
            v, i = numbers(tok, i + 3, 3 * n)
            out["points"] = v.reshape(n, 3)
        elif key == "POLYGONS":
            n = int(tok[i + 1])
            v, i = numbers(tok, i + 3, 4 * n, int)
            v = v.reshape(n, 4)
            if (v[:, 0] != 3).any():
                fail("only triangles are drawn")
            out["tris"] = v[:, 1:]
        elif key == "POINT_DATA":
            i += 2
        elif key == "VECTORS":
            name = tok[i + 1]
            v, i = numbers(tok, i + 3, 3 * len(out["points"]))
            out[name] = v.reshape(-1, 3)
        else:
            fail(f"{path}: unexpected '{key}'")
    for need in ("points", "tris", "displacement_m"):
        if need not in out:
            fail(f"{path}: no {need}")
    out["field"] = field
    return out


def read_vtu(path):
    """The same dict from irdm render's UnstructuredGrid of triangles."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        fail(f"{path}: {e}")
    grid = root.find("UnstructuredGrid")
    if root.get("type") != "UnstructuredGrid" or grid is None:
        fail(f"{path}: not a VTK UnstructuredGrid")

    def arrays(node):
        return {a.get("Name"): np.array((a.text or "").split(), dtype=float)
                for a in (node.findall("DataArray") if node is not None else [])}

    piece = grid.find("Piece")
    n = int(piece.get("NumberOfPoints"))
    pts = np.array(piece.find("Points/DataArray").text.split(), dtype=float).reshape(n, 3)
    cells = arrays(piece.find("Cells"))
    if (cells["types"] != 5).any():
        fail(f"{path}: only triangles are drawn")
    out = {"points": pts, "tris": cells["connectivity"].astype(int).reshape(-1, 3)}
    out["displacement_m"] = arrays(piece.find("PointData"))["displacement_m"].reshape(n, 3)
    field = arrays(grid.find("FieldData"))
    out["field"] = {"time_s": field["time_s"].reshape(1, 1),
                    "contact": field["contact"].reshape(-1, 1),
                    "contact_point_m": field["contact_point_m"].reshape(-1, 3),
                    "contact_force_n": field["contact_force_n"].reshape(-1, 3)}
    return out


def read_frames(path):
    """A .pvd's frames in order, or the one file."""
    if path.endswith(".pvd"):
        base = os.path.dirname(path)
        try:
            sets = ET.parse(path).getroot().findall("Collection/DataSet")
        except (OSError, ET.ParseError) as e:
            fail(f"{path}: {e}")
        return [os.path.join(base, d.get("file")) for d in sets]
    return [path]


def read_frame(path):
    return read_vtu(path) if path.endswith(".vtu") else read_vtk(path)


def shaded(pts, tris, colors):
    """Lambert shading by hand (older matplotlib has no shade= for polygons)."""
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    light = np.array([-0.4, -0.6, 0.7])
    light /= np.linalg.norm(light)
    k = 0.45 + 0.55 * np.abs(n @ light)
    out = colors.copy()
    out[:, :3] *= k[:, None]
    return out


def draw(ax, d, scale, norm, cmap, size):
    """One frame on ax: the exaggerated surface, its contact and force."""
    u = d["displacement_m"]
    rest = d["points"] - u
    shown = rest + scale * u
    tri_mag = (np.linalg.norm(u, axis=1) * 1e3)[d["tris"]].mean(axis=1)
    poly = Poly3DCollection(shown[d["tris"]], facecolors=shaded(shown, d["tris"],
                                                                cmap(norm(tri_mag))),
                            edgecolor=(0, 0, 0, 0.15), linewidth=0.2)
    poly.set_zorder(1)
    ax.add_collection3d(poly)
    f = d["field"]
    for i, on in enumerate(f.get("contact", np.zeros((0, 1)))[:, 0]):
        if not on:
            continue
        p = f["contact_point_m"][i]
        # the contact point rides on the exaggerated surface like its nodes
        near = np.argmin(np.linalg.norm(d["points"] - p, axis=1))
        p_shown = p + (scale - 1) * u[near]
        force = f["contact_force_n"][i]
        fn = np.linalg.norm(force)
        if fn > 0:
            arrow = force / fn * 0.3 * size     # along the force, ending at the contact
            ax.quiver(*(p_shown - arrow), *arrow, color="red", linewidth=2.5,
                      arrow_length_ratio=0.25, zorder=10)
        ax.scatter(*p_shown, color="red", s=30, depthshade=False, zorder=11,
                   label=f"contact {i + 1}, force on the object {fn:.3f} N")
        ax.legend(loc="upper left", fontsize=8)
    # the rest shape sets the view: the same in every frame of a film
    lo, hi = rest.min(axis=0), rest.max(axis=0)
    mid, half = (lo + hi) / 2, (hi - lo).max() / 2 * 1.15
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), mid):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.view_init(elev=28, azim=-55)
    return f.get("time_s", [[float("nan")]])[0][0]


def options(argv):
    """Frames, other arguments, and the --scale, --each, --step values."""
    opts = {"scale": None, "each": None, "step": 1}
    rest, srcs, i = [], [], 0
    while i < len(argv):
        a = argv[i]
        if a.startswith("--scale="):
            opts["scale"] = float(a.split("=", 1)[1])
        elif a.startswith("--step="):
            opts["step"] = int(a.split("=", 1)[1])
        elif a == "--each" and i + 1 < len(argv):
            opts["each"], i = argv[i + 1], i + 1
        elif a.endswith((".vtk", ".vtu", ".pvd")):
            srcs += read_frames(a)
        else:
            rest.append(a)
        i += 1
    if not srcs or (opts["each"] is None and not rest) or opts["step"] < 1:
        fail(__doc__.strip().split("usage: ")[-1])
    return srcs, rest, opts


def ranges(frames, scale):
    """One scale and one colour range for every frame: they compare."""
    size = max(np.ptp(d["points"] - d["displacement_m"], axis=0).max() for d in frames)
    umax = max(np.linalg.norm(d["displacement_m"], axis=1).max() for d in frames)
    if scale is None:
        scale = 0.1 * size / umax if umax > 0 else 1.0
    return size, scale, matplotlib.colors.Normalize(0, max(umax * 1e3, 1e-12))


def each(srcs, outdir, title, opts):
    """One PNG per frame (every step-th), for a film."""
    srcs = srcs[::opts["step"]]
    frames = [read_frame(src) for src in srcs]
    size, scale, norm = ranges(frames, opts["scale"])
    cmap = plt.get_cmap("viridis")
    os.makedirs(outdir, exist_ok=True)
    for src, d in zip(srcs, frames):
        fig = plt.figure(figsize=(6.4, 6))
        ax = fig.add_subplot(1, 1, 1, projection="3d", computed_zorder=False)
        t = draw(ax, d, scale, norm, cmap, size)
        mag = np.linalg.norm(d["displacement_m"], axis=1).max() * 1e3
        ax.set_title(f"{title}\nt = {t:.3f} s, max |u| = {mag:.2f} mm (shape x{scale:.1f})",
                     fontsize=9)
        fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.6,
                     label="|displacement| (mm)")
        name = os.path.splitext(os.path.basename(src))[0] + ".png"
        fig.savefig(os.path.join(outdir, name), dpi=90)
        plt.close(fig)
    print(f"plot-surface: {len(frames)} frames -> {outdir}/")


def main():
    srcs, rest_args, opts = options(sys.argv[1:])
    if opts["each"] is not None:
        each(srcs, opts["each"], rest_args[0] if rest_args else srcs[0], opts)
        return
    dst = rest_args[0]
    title = rest_args[1] if len(rest_args) > 1 else srcs[0]
    frames = [read_frame(src) for src in srcs]
    size, scale, norm = ranges(frames, opts["scale"])
    cmap = plt.get_cmap("viridis")
    n = len(frames)
    fig = plt.figure(figsize=(7.5 if n == 1 else 4.2 * n, 7 if n == 1 else 4.8))
    for k, d in enumerate(frames):
        # drawn in call order: the arrow and the point stay on top of the surface
        ax = fig.add_subplot(1, n, k + 1, projection="3d", computed_zorder=False)
        t = draw(ax, d, scale, norm, cmap, size)
        mag = np.linalg.norm(d["displacement_m"], axis=1).max() * 1e3
        if n == 1:
            ax.set_title(f"{title}\nt = {t:.3f} s, max |u| = {mag:.2f} mm "
                         f"(shape x{scale:.1f})", fontsize=9)
        else:
            ax.set_title(f"t = {t:.2f} s, max |u| = {mag:.2f} mm", fontsize=9)
    if n > 1:
        fig.suptitle(f"{title} (shape x{scale:.1f})", fontsize=10)
    sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=fig.axes, shrink=0.6, label="|displacement| (mm)")
    fig.savefig(dst, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
