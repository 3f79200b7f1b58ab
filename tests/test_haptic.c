/* SPDX-License-Identifier: MIT */
/*
 * The haptic path end to end: a device position drives the proxy on the
 * image's surface (BVH, frictionless god-object), the proxy's site and the
 * device drive the engine through the virtual coupling.  A push, a quick
 * pull-out that leaves the cuboid ringing, and a return while it still
 * vibrates: the proxy must touch the surface where it is now, not where it
 * rests.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "irdm/contact.h"
#include "irdm/posix/image_map.h"
#include "support/engine_fixture.h"

static void engine_disp(const void *ctx, uint32_t row, double u[3])
{
	irdm_engine_node_disp(ctx, row, u);
}

static void test_retouch_sees_the_deformed_surface(void **state)
{
	char dir[64] = "/tmp/irdm-haptic-XXXXXX", path[128], cmdline[128];
	struct irdm_image img;
	struct irdm_engine_config cfg;
	struct irdm_contact_mesh cm;
	struct irdm_proxy px;
	struct irdm_proxy_config pcfg;
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];

	(void)state;
	assert_non_null(mkdtemp(dir));
	snprintf(path, sizeof(path), "%s/c.img", dir);
	efx_image(&img, path, "resolution", "4,4,8", "representation", "modal:60", "touch", "z>=0.2",
		  "display", "touch", NULL);
	irdm_engine_config_haptic(&cfg, img.meta->dt_s, 1000, 5, 7.9);
	cfg.max_contacts = 1;
	struct irdm_session *ses = efx_session(&img, &cfg);
	struct irdm_engine *e = ses->eng;
	cm = ses->cm; /* with the session's face-beyond table */
	assert_non_null(cm.beyond);
	irdm_proxy_config_default(&pcfg);
	pcfg.max_disp_m = 0.05;
	irdm_proxy_reset(&px);
	struct irdm_contact_disp disp = { .u_m = NULL, .fn = engine_disp, .ctx = e };

	/* device: down 1.5 cm into the top in 0.2 s, hold 0.3 s, out 3 cm in
	 * 10 ms, wait 40 ms, then down again at 5 cm/s */
	double z_touch = NAN, surface_touch = NAN, max_f = 0;
	int touches = 0;
	bool was_active = false;
	for (int t = 0; t < 1500; t++) {
		double ms = t, z;
		if (ms < 200)
			z = 0.205 - 0.02 * ms / 200;
		else if (ms < 500)
			z = 0.185;
		else if (ms < 510)
			z = 0.185 + 0.03 * (ms - 500) / 10;
		else if (ms < 550)
			z = 0.215;
		else
			z = 0.215 - 0.05 * (ms - 550) / 1000;
		double p[3] = { 0.05, 0.05, z };
		irdm_proxy_update(&px, &cm, &disp, &pcfg, p);
		memset(cmd, 0, sizeof(cmd));
		if (px.active) {
			struct irdm_contact_site site;
			assert_int_equal(irdm_proxy_site(&px, &cm, &site), 0);
			assert_int_equal(irdm_engine_contact_begin(e, 0, &site, IRDM_CONTACT_PUSH), 0);
			cmd[0].mode = IRDM_CONTACT_PUSH;
			for (int a = 0; a < 3; a++)
				cmd[0].target_m[a] = p[a] - site.rest_m[a];
			if (!was_active) {
				touches++;
				if (t > 550 && isnan(z_touch)) {
					z_touch = z;
					surface_touch = px.point_m[2];
				}
			}
		}
		was_active = px.active;
		assert_int_equal(irdm_engine_tick(e, cmd), 0);
		const double *f = irdm_engine_contact(e, 0)->force_n;
		max_f = fmax(max_f, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
	}
	print_message("touches %d; re-touch at device z %.5f m on the surface at %.5f m (rest 0.2 m); max |F| %.3f N\n",
		      touches, z_touch, surface_touch, max_f);
	assert_true(touches >= 2);
	assert_false(isnan(z_touch));
	/* the surface it met was displaced by the ringing, and the device met it
	 * within one tick's travel (5e-5 m) below the displaced surface */
	assert_true(fabs(surface_touch - 0.2) > 5e-4);
	assert_true(surface_touch - z_touch >= 0 && surface_touch - z_touch < 1e-4);
	assert_true(max_f <= 7.9);
	irdm_session_close(ses);
	irdm_image_unmap(&img);
	snprintf(cmdline, sizeof(cmdline), "rm -rf '%s'", dir);
	assert_int_equal(system(cmdline), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_retouch_sees_the_deformed_surface),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
