/* SPDX-License-Identifier: MIT */
/* The project's version, one place for every tool that records it. */
#ifndef IRDM_VERSION_H
#define IRDM_VERSION_H

#define IRDM_VERSION "0.1.0"

#endif
