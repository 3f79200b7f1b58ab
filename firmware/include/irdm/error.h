/* SPDX-License-Identifier: MIT */
/*
 * One error space for the whole project: firmware, HAL, simulator and the
 * offline tools.  A function that can fail returns IRDM_OK (0) or one of the
 * negative codes below, and documents which ones; a one-line reason, where
 * the function takes an `err` buffer, says what failed and why.  Codes are
 * stable: tests, logs and exit paths may print and compare them.
 */
#ifndef IRDM_ERROR_H
#define IRDM_ERROR_H

enum irdm_err {
	IRDM_OK = 0,
	IRDM_EINVAL = -1,     /* invalid argument or configuration */
	IRDM_ENOMEM = -2,     /* out of memory, or the memory given is too small */
	IRDM_EIO = -3,        /* cannot open, read, write, stat, map or lock a file */
	IRDM_ETRUNC = -4,     /* input shorter than it says it is */
	IRDM_EMAGIC = -5,     /* not an IRDM image */
	IRDM_EVERSION = -6,   /* unsupported format version */
	IRDM_ECRC = -7,       /* checksum mismatch */
	IRDM_ERANGE = -8,     /* offset, size or alignment out of range or overlapping */
	IRDM_EMISSING = -9,   /* a required part is absent or duplicated */
	IRDM_EFORMAT = -10,   /* malformed input: a field, line or value is invalid */
	IRDM_ECONTACT = -11,  /* contact location not touchable */
	IRDM_EFAULT = -12,    /* non-finite input or a limit exceeded: faulted, torque off */
	IRDM_EBUSY = -13,     /* already running */
	IRDM_ETHREAD = -14,   /* a thread could not be created */
	IRDM_ENUMERIC = -15,  /* a numerical method failed (factorisation, eigensolver) */
	IRDM_ENOTSUP = -16,   /* not supported by this build or this input */
	IRDM_EPERM = -17,     /* the system refused a privilege (real-time, memory lock) */
	IRDM_ETIMEDOUT = -18, /* a deadline or a time-out passed */
	IRDM_EHW = -19,       /* the hardware or its link reported a fault */
	IRDM_ECHILD = -20,    /* an external program failed */
	IRDM_EEXIST = -21,    /* an output's target exists and is not the tool's to replace */
};

#define IRDM_ERR_MIN IRDM_EEXIST

/* Short description, e.g. "out of memory"; "unknown error" outside the space. */
const char *irdm_strerror(int code);

/* Symbolic name, e.g. "ENOMEM" (without the IRDM_ prefix); "E?" outside it. */
const char *irdm_errname(int code);

#endif /* IRDM_ERROR_H */
