/* SPDX-License-Identifier: MIT */
/*
 * The CAN port on a SocketCAN raw socket (irdm/socketcan.h).  Opening
 * checks everything it can once (the kernel has CAN, the interface exists
 * and is up); send and recv are then one non-blocking system call each and
 * map the errno a dead link gives to IRDM_EIO.
 */
#include <errno.h>
#include <fcntl.h>
#include <net/if.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>

#include "irdm/error.h"
#include "irdm/hal/socketcan.h"

/* The error classes we want delivered: the ones that say the link is
 * unusable (bus-off) or going bad (controller: error passive, overflows). */
#define ERR_MASK (CAN_ERR_BUSOFF | CAN_ERR_CRTL | CAN_ERR_RESTARTED)

static void say(char *err, size_t errlen, const char *fmt, const char *ifname, int e)
{
	if (err && errlen)
		snprintf(err, errlen, fmt, ifname, strerror(e));
}

/* errno of a failed read/write: does it mean the link is gone? */
static bool link_gone(int e)
{
	return e == ENETDOWN || e == ENODEV || e == ENXIO || e == EBADF;
}

static void error_frame(struct irdm_socketcan *s, const struct can_frame *cf)
{
	s->error_frames++;
	if (cf->can_id & CAN_ERR_BUSOFF)
		s->bus_off = true;
	if ((cf->can_id & CAN_ERR_CRTL) && cf->len >= 2 &&
	    (cf->data[1] & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)))
		s->error_passive = true;
	if (cf->can_id & CAN_ERR_RESTARTED)
		s->error_passive = false; /* the controller came back error active */
}

static int sc_send(void *ctx, const struct irdm_can_frame *f)
{
	struct irdm_socketcan *s = ctx;
	struct can_frame cf;
	ssize_t n;

	if (s->fd < 0 || s->bus_off)
		return IRDM_EIO;
	if (f->id > CAN_SFF_MASK || f->dlc > CAN_MAX_DLEN)
		return IRDM_EINVAL; /* ours to check: the kernel would take an EFF id */
	memset(&cf, 0, sizeof(cf));
	cf.can_id = f->id;
	cf.len = f->dlc;
	memcpy(cf.data, f->data, f->dlc);
	n = write(s->fd, &cf, sizeof(cf));
	if (n == (ssize_t)sizeof(cf))
		return IRDM_OK;
	if (n < 0 && (errno == ENOBUFS || errno == EAGAIN)) {
		s->tx_dropped++;
		return IRDM_EBUSY;
	}
	return IRDM_EIO; /* link gone, or a short write: never normal */
}

static int sc_recv(void *ctx, struct irdm_can_frame *f)
{
	struct irdm_socketcan *s = ctx;
	struct can_frame cf;
	ssize_t n;

	if (s->fd < 0 || s->bus_off)
		return IRDM_EIO;
	n = read(s->fd, &cf, sizeof(cf));
	if (n < 0)
		return link_gone(errno) ? IRDM_EIO : 0; /* EAGAIN: nothing waiting */
	if (n == (ssize_t)sizeof(cf) && (cf.can_id & CAN_ERR_FLAG)) {
		error_frame(s, &cf);
		return s->bus_off ? IRDM_EIO : 0;
	}
	if (n != (ssize_t)sizeof(cf) || (cf.can_id & (CAN_RTR_FLAG | CAN_EFF_FLAG)) ||
	    cf.len > CAN_MAX_DLEN) {
		s->rx_rejected++;
		return 0;
	}
	f->id = cf.can_id & CAN_SFF_MASK;
	f->dlc = cf.len;
	memset(f->data, 0, sizeof(f->data));
	memcpy(f->data, cf.data, cf.len);
	return 1;
}

static const struct irdm_can_port_ops socketcan_ops = { sc_send, sc_recv };

/* The socket's options and binding: IRDM_OK, or the reason in err. */
static int setup(struct irdm_socketcan *s, char *err, size_t errlen)
{
	can_err_mask_t mask = ERR_MASK;
	struct sockaddr_can addr;
	struct ifreq ifr;
	int flags;

	memset(&ifr, 0, sizeof(ifr));
	memcpy(ifr.ifr_name, s->ifname, sizeof(s->ifname));
	if (ioctl(s->fd, SIOCGIFINDEX, &ifr) < 0) {
		say(err, errlen, "socketcan: interface %s: %s", s->ifname, errno);
		return IRDM_EIO;
	}
	memset(&addr, 0, sizeof(addr));
	addr.can_family = AF_CAN;
	addr.can_ifindex = ifr.ifr_ifindex;
	if (setsockopt(s->fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof(mask)) < 0 ||
	    bind(s->fd, (struct sockaddr *)&addr, sizeof(addr)) < 0 ||
	    (flags = fcntl(s->fd, F_GETFL)) < 0 || fcntl(s->fd, F_SETFL, flags | O_NONBLOCK) < 0) {
		say(err, errlen, "socketcan: %s: cannot set up the socket: %s", s->ifname, errno);
		return IRDM_EIO;
	}
	if (ioctl(s->fd, SIOCGIFFLAGS, &ifr) < 0 || !(ifr.ifr_flags & IFF_UP)) {
		if (err && errlen)
			snprintf(err, errlen, "socketcan: interface %s is down", s->ifname);
		return IRDM_EIO;
	}
	return IRDM_OK;
}

int irdm_socketcan_open(struct irdm_socketcan *s, const char *ifname, struct irdm_can_port *port,
			char *err, size_t errlen)
{
	size_t len = ifname ? strnlen(ifname, IRDM_SOCKETCAN_IFNAME_MAX) : 0;
	int rc;

	memset(s, 0, sizeof(*s));
	s->fd = -1;
	if (len == 0 || len >= IRDM_SOCKETCAN_IFNAME_MAX) {
		if (err && errlen)
			snprintf(err, errlen, "socketcan: interface name must be 1..%d characters",
				 IRDM_SOCKETCAN_IFNAME_MAX - 1);
		return IRDM_EINVAL;
	}
	memcpy(s->ifname, ifname, len);
	s->fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
	if (s->fd < 0) {
		int e = errno;

		say(err, errlen, "socketcan: %s: this kernel has no CAN sockets: %s", s->ifname, e);
		return e == EAFNOSUPPORT || e == EPROTONOSUPPORT || e == EINVAL ? IRDM_ENOTSUP : IRDM_EIO;
	}
	rc = setup(s, err, errlen);
	if (rc != IRDM_OK) {
		irdm_socketcan_close(s);
		return rc;
	}
	port->ops = &socketcan_ops;
	port->ctx = s;
	return IRDM_OK;
}

void irdm_socketcan_close(struct irdm_socketcan *s)
{
	if (s->fd >= 0)
		close(s->fd);
	s->fd = -1;
}
