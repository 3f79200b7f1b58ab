/* SPDX-License-Identifier: MIT */
/*
 * A CAN port (irdm/can_port.h) on a Linux SocketCAN interface: one raw
 * socket (CAN_RAW), non-blocking, with the controller's error frames
 * (bus-off, error passive, controller problems) delivered to recv as
 * IRDM_EIO or counted.  Nothing is allocated: the caller owns the struct.
 * Opening and closing are system calls made at start and end; send and
 * recv are one non-blocking system call each (the HAL back-end's own I/O,
 * the only system calls the force tick may make).
 *
 * Through the port: send returns IRDM_OK, IRDM_EBUSY when the interface's
 * queue is full (ENOBUFS/EAGAIN, counted in tx_dropped), IRDM_EINVAL for a
 * frame no classical controller sends (id > 0x7FF, dlc > 8), IRDM_EIO when
 * the link is gone (bus-off latched, ENETDOWN, ENODEV).  recv returns 1
 * with a frame, IRDM_EIO as send, or 0: nothing waiting, or the one frame
 * its system call read was not data (an error frame, counted and latched;
 * an RTR or extended-id frame or a wrong size, counted in rx_rejected), so
 * a caller that drains until 0 may leave frames for its next call.
 * bus_off stays latched until the socket is closed and opened again.
 */
#ifndef IRDM_SOCKETCAN_H
#define IRDM_SOCKETCAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "irdm/hal/can_port.h"

#define IRDM_SOCKETCAN_IFNAME_MAX 16 /* IFNAMSIZ */

struct irdm_socketcan {
	int fd; /* -1: closed */
	char ifname[IRDM_SOCKETCAN_IFNAME_MAX];
	bool bus_off;          /* latched: an error frame said bus-off */
	bool error_passive;    /* latched: an error frame said error passive */
	uint64_t error_frames; /* error frames seen */
	uint64_t tx_dropped;   /* sends refused: queue full (ENOBUFS/EAGAIN) */
	uint64_t rx_rejected;  /* frames read but not data: RTR, extended id, size */
};

/*
 * Open a raw CAN socket bound to interface ifname, non-blocking, receiving
 * error frames; *port then sends and receives through it.
 * Return: IRDM_OK; IRDM_EINVAL if ifname is empty or too long;
 * IRDM_ENOTSUP if the kernel has no CAN (socket() refuses PF_CAN);
 * IRDM_EIO if the interface does not exist or is down; err (if given)
 * says which and why in one line.
 */
int irdm_socketcan_open(struct irdm_socketcan *s, const char *ifname, struct irdm_can_port *port,
			char *err, size_t errlen);

/* Close the socket (harmless on a closed one). */
void irdm_socketcan_close(struct irdm_socketcan *s);

#endif /* IRDM_SOCKETCAN_H */
