/* SPDX-License-Identifier: MIT */
/*
 * The SocketCAN port (irdm/socketcan.h).  Everywhere: bad interface names
 * are refused.  On a kernel without CAN (the build host): opening fails
 * with IRDM_ENOTSUP and one line.  With IRDM_SOCKETCAN_TEST_IF set to a
 * virtual CAN interface that is up (make hil's VM: vcan0) the real path:
 * frames round-trip, a node does not hear itself, RTR / extended-id frames
 * are refused and counted, a bus-off error frame latches and makes send
 * and recv fail, an interface taken down makes them fail, a down or
 * missing interface cannot be opened.  Each test that needs the other
 * kernel skips (cmocka's skip()) rather than passing without checking.
 */
#include <errno.h>
#include <net/if.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>
#include <linux/can.h>
#include <linux/can/error.h>

#include "irdm/error.h"
#include "irdm/hal/socketcan.h"

static bool kernel_has_can(void)
{
	int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);

	if (fd < 0)
		return false;
	close(fd);
	return true;
}

/* The interface the real-path tests use, or skip. */
static const char *test_if(void)
{
	const char *ifname = getenv("IRDM_SOCKETCAN_TEST_IF");

	if (!ifname || !*ifname || !kernel_has_can())
		skip();
	return ifname;
}

static void test_bad_names(void **state)
{
	struct irdm_socketcan s;
	struct irdm_can_port port;
	char err[128] = "";

	(void)state;
	assert_int_equal(irdm_socketcan_open(&s, "", &port, err, sizeof(err)), IRDM_EINVAL);
	assert_non_null(strstr(err, "interface name"));
	assert_int_equal(irdm_socketcan_open(&s, NULL, &port, err, sizeof(err)), IRDM_EINVAL);
	assert_int_equal(irdm_socketcan_open(&s, "a-name-too-long0", &port, err, sizeof(err)),
			 IRDM_EINVAL);
	assert_int_equal(s.fd, -1);
	irdm_socketcan_close(&s); /* harmless on a closed one */
}

static void test_no_can_kernel(void **state)
{
	struct irdm_socketcan s;
	struct irdm_can_port port;
	char err[128] = "";

	(void)state;
	if (kernel_has_can())
		skip();
	assert_int_equal(irdm_socketcan_open(&s, "vcan0", &port, err, sizeof(err)),
			 IRDM_ENOTSUP);
	assert_non_null(strstr(err, "vcan0: this kernel has no CAN sockets"));
	assert_null(strchr(err, '\n'));
	assert_int_equal(s.fd, -1);
}

static void open_pair(const char *ifname, struct irdm_socketcan *a, struct irdm_can_port *pa,
		      struct irdm_socketcan *b, struct irdm_can_port *pb)
{
	char err[128] = "";

	assert_int_equal(irdm_socketcan_open(a, ifname, pa, err, sizeof(err)), IRDM_OK);
	assert_int_equal(irdm_socketcan_open(b, ifname, pb, err, sizeof(err)), IRDM_OK);
}

static void test_round_trip(void **state)
{
	const char *ifname = test_if();
	struct irdm_socketcan a, b;
	struct irdm_can_port pa, pb;
	struct irdm_can_frame f = { .id = 0x201, .dlc = 4, .data = { 1, 2, 3, 4 } }, g;
	struct irdm_can_frame wide = { .id = 0x800, .dlc = 1 };

	(void)state;
	open_pair(ifname, &a, &pa, &b, &pb);
	assert_int_equal(irdm_can_recv(&pb, &g), 0); /* nothing yet, no block */
	assert_int_equal(irdm_can_send(&pa, &f), IRDM_OK);
	assert_int_equal(irdm_can_recv(&pb, &g), 1);
	assert_int_equal(g.id, 0x201);
	assert_int_equal(g.dlc, 4);
	assert_memory_equal(g.data, f.data, 4);
	assert_int_equal(g.data[4], 0);
	assert_int_equal(irdm_can_recv(&pa, &g), 0); /* not its own */
	assert_int_equal(irdm_can_send(&pa, &wide), IRDM_EINVAL);
	irdm_socketcan_close(&a);
	irdm_socketcan_close(&b);
}

/* A frame written on a plain raw socket, bypassing the port's checks. */
static void raw_write(const char *ifname, canid_t id, uint8_t len)
{
	struct irdm_socketcan w;
	struct irdm_can_port pw;
	struct can_frame cf;
	char err[128];

	assert_int_equal(irdm_socketcan_open(&w, ifname, &pw, err, sizeof(err)), IRDM_OK);
	memset(&cf, 0, sizeof(cf));
	cf.can_id = id;
	cf.len = len;
	assert_int_equal(write(w.fd, &cf, sizeof(cf)), (ssize_t)sizeof(cf));
	irdm_socketcan_close(&w);
}

static void test_rejects_rtr_and_extended(void **state)
{
	const char *ifname = test_if();
	struct irdm_socketcan b;
	struct irdm_can_port pb;
	struct irdm_can_frame g;
	char err[128];

	(void)state;
	assert_int_equal(irdm_socketcan_open(&b, ifname, &pb, err, sizeof(err)), IRDM_OK);
	raw_write(ifname, 0x181 | CAN_RTR_FLAG, 0);
	raw_write(ifname, 0x181 | CAN_EFF_FLAG, 6);
	raw_write(ifname, 0x181, 6);
	assert_int_equal(irdm_can_recv(&pb, &g), 0);
	assert_int_equal(irdm_can_recv(&pb, &g), 0);
	assert_int_equal(b.rx_rejected, 2);
	assert_int_equal(irdm_can_recv(&pb, &g), 1);
	assert_int_equal(g.id, 0x181);
	irdm_socketcan_close(&b);
}

static void test_error_frames_latch(void **state)
{
	const char *ifname = test_if();
	struct irdm_socketcan b;
	struct irdm_can_port pb;
	struct irdm_can_frame g, f = { .id = 0x201, .dlc = 0 };
	char err[128];

	(void)state;
	assert_int_equal(irdm_socketcan_open(&b, ifname, &pb, err, sizeof(err)), IRDM_OK);
	{
		/* error passive: counted and latched, the link still works */
		struct irdm_socketcan w;
		struct irdm_can_port pw;
		struct can_frame cf = { .can_id = CAN_ERR_FLAG | CAN_ERR_CRTL, .len = CAN_ERR_DLC };

		cf.data[1] = CAN_ERR_CRTL_TX_PASSIVE;
		assert_int_equal(irdm_socketcan_open(&w, ifname, &pw, err, sizeof(err)), IRDM_OK);
		assert_int_equal(write(w.fd, &cf, sizeof(cf)), (ssize_t)sizeof(cf));
		irdm_socketcan_close(&w);
	}
	assert_int_equal(irdm_can_recv(&pb, &g), 0);
	assert_true(b.error_passive);
	assert_false(b.bus_off);
	assert_int_equal(b.error_frames, 1);
	assert_int_equal(irdm_can_send(&pb, &f), IRDM_OK);
	raw_write(ifname, CAN_ERR_FLAG | CAN_ERR_BUSOFF, CAN_ERR_DLC);
	assert_int_equal(irdm_can_recv(&pb, &g), IRDM_EIO);
	assert_true(b.bus_off);
	assert_int_equal(b.error_frames, 2);
	assert_int_equal(irdm_can_send(&pb, &f), IRDM_EIO); /* latched */
	assert_int_equal(irdm_can_recv(&pb, &g), IRDM_EIO);
	irdm_socketcan_close(&b);
}

static void set_up(const char *ifname, bool up)
{
	struct ifreq ifr;
	int fd = socket(AF_INET, SOCK_DGRAM, 0);

	assert_true(fd >= 0);
	memset(&ifr, 0, sizeof(ifr));
	strncpy(ifr.ifr_name, ifname, IFNAMSIZ - 1);
	assert_int_equal(ioctl(fd, SIOCGIFFLAGS, &ifr), 0);
	if (up)
		ifr.ifr_flags |= IFF_UP;
	else
		ifr.ifr_flags &= ~IFF_UP;
	assert_int_equal(ioctl(fd, SIOCSIFFLAGS, &ifr), 0);
	close(fd);
}

static void test_interface_down(void **state)
{
	const char *ifname = test_if();
	struct irdm_socketcan a, b;
	struct irdm_can_port pa, pb;
	struct irdm_can_frame g, f = { .id = 0x201, .dlc = 0 };
	char err[128] = "";

	(void)state;
	open_pair(ifname, &a, &pa, &b, &pb);
	set_up(ifname, false);
	assert_int_equal(irdm_can_send(&pa, &f), IRDM_EIO);
	assert_int_equal(irdm_can_recv(&pb, &g), IRDM_EIO); /* the socket's ENETDOWN */
	irdm_socketcan_close(&a);
	assert_int_equal(irdm_socketcan_open(&a, ifname, &pa, err, sizeof(err)), IRDM_EIO);
	assert_non_null(strstr(err, "is down"));
	set_up(ifname, true);
	assert_int_equal(irdm_socketcan_open(&a, "nocan9", &pa, err, sizeof(err)), IRDM_EIO);
	assert_non_null(strstr(err, "interface nocan9"));
	irdm_socketcan_close(&a);
	irdm_socketcan_close(&b);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_bad_names),
		cmocka_unit_test(test_no_can_kernel),
		cmocka_unit_test(test_round_trip),
		cmocka_unit_test(test_rejects_rtr_and_extended),
		cmocka_unit_test(test_error_frames_latch),
		cmocka_unit_test(test_interface_down),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
