/* SPDX-License-Identifier: MIT */
/*
 * What this build of the firmware carries (docs/build-config.md).  Each
 * feature is in (1) unless the build says otherwise: `make
 * CONFIG=configs/NAME.config` passes -DIRDM_CONFIG_X=0 for every
 * CONFIG_IRDM_X that is not y, and leaves the feature's files out of the
 * link.  A build without a feature refuses, at set-up and by name, an
 * image or a board that needs it (IRDM_ENOTSUP).
 */
#ifndef IRDM_BUILD_CONFIG_H
#define IRDM_BUILD_CONFIG_H

#ifndef IRDM_CONFIG_FIR
#define IRDM_CONFIG_FIR 1 /* FIR (time-domain) images: engine_fir.c */
#endif
#ifndef IRDM_CONFIG_MODAL
#define IRDM_CONFIG_MODAL 1 /* modal images: engine_modal.c */
#endif
#ifndef IRDM_CONFIG_FLOATING
#define IRDM_CONFIG_FLOATING 1 /* floating objects: engine/floating.c, rigid/ */
#endif
#ifndef IRDM_CONFIG_DEFORM
#define IRDM_CONFIG_DEFORM 1 /* the displayed surface: deform/, session_deform.c */
#endif

#endif /* IRDM_BUILD_CONFIG_H */
