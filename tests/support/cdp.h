/* SPDX-License-Identifier: MIT */
/*
 * Headless Chromium driven over the DevTools protocol on a pipe
 * (--remote-debugging-pipe: commands on its fd 3, replies on its fd 4,
 * each a NUL-terminated JSON message): open a page, evaluate JavaScript,
 * take a PNG screenshot.  Tests only; cmocka inside.
 */
#ifndef IRDM_TESTS_CDP_H
#define IRDM_TESTS_CDP_H

#include <stdbool.h>
#include <stddef.h>

struct cdp;

/* The browser to use: $IRDM_CHROMIUM, else /usr/bin/chromium; NULL if it
 * is not there (the caller skips, saying so). */
const char *cdp_browser(void);

/* Start the browser (its output in dir/chromium.log) on url, the window
 * w x h CSS pixels at scale 1.  Fails the test if it does not come up. */
struct cdp *cdp_open(const char *dir, const char *url, int w, int h);

/* Evaluate expr in the page; its value as a string (the expression should
 * give a string) into out.  Returns false if the page threw. */
bool cdp_eval(struct cdp *c, const char *expr, char *out, size_t outlen);

/* The page as PNG bytes (malloc'd; *len their count). */
unsigned char *cdp_screenshot(struct cdp *c, size_t *len);

/* Close the browser and wait for it. */
void cdp_close(struct cdp *c);

#endif
