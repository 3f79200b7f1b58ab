/* SPDX-License-Identifier: MIT */
/* irdm report run from a test, and its CSV read back. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "engine_fixture.h"
#include "irdm/session.h"

#include "report_fixture.h"
#include "run_prog.h"
#include "test_files.h"

int rfx_run(char *dir, size_t len, const char *config)
{
	const char *irdm = getenv("IRDM") ? getenv("IRDM") : "build/irdm";
	char base[256], out[320], err[4096];
	const char *args[] = { "report", "--config", config, "-o", out, "--keep-images", "-q", NULL };
	int rc;

	/* the report's own directory beside the run's stdout and stderr: it
	 * replaces only a directory it wrote */
	if (tf_tmpdir(base, sizeof(base), "report"))
		return -1;
	snprintf(out, sizeof(out), "%s/out", base);
	snprintf(dir, len, "%s", out);
	rc = rp_run(base, irdm, args, NULL, 0, err, sizeof(err));
	if (rc)
		fprintf(stderr, "irdm report --config %s: exit %d: %s\n", config, rc, err);
	return rc ? -1 : 0;
}

int rfx_remove(const char *dir)
{
	char base[320];
	char *slash;

	snprintf(base, sizeof(base), "%s", dir);
	slash = strrchr(base, '/');
	if (!slash || strcmp(slash, "/out"))
		return -1;
	*slash = '\0';
	return tf_rmdir(base);
}

/* config,repr,dt_ms,scenario,force_err,first10,after100,disp_err,median,p99,
 * bytes,radius,cert_stable,run_bounded,raw_growth,ticks,paper,keys */
int rfx_read_csv(const char *dir, const char *config, struct rfx_row *rows, int max)
{
	char path[512], text[8192], cfg[32], *save = NULL;
	int line = 0, n = 0;

	snprintf(path, sizeof(path), "%s/report-%s.csv", dir, config);
	tf_read_text(path, text, sizeof(text));
	for (char *l = strtok_r(text, "\n", &save); l; l = strtok_r(NULL, "\n", &save), line++) {
		struct rfx_row *r = &rows[n];

		if (!line)
			continue;
		assert_true(n < max);
		assert_int_equal(sscanf(l, "%31[^,],%47[^,],%lf,%31[^,],%lf,%lf,%lf,%lf,%lf,%lf,%zu,%lf,%d,%d,%lf,%zu,%d,",
					cfg, r->repr, &r->dt_ms, r->scenario, &r->force_err, &r->first10,
					&r->after100, &r->disp_err, &r->median_us, &r->p99_us, &r->bytes,
					&r->radius, &r->cert_stable, &r->bounded, &r->growth, &r->ticks,
					&r->paper),
				 17);
		assert_string_equal(cfg, config);
		n++;
	}
	return n;
}

const struct rfx_row *rfx_row_of(const struct rfx_row *rows, int n, const char *repr,
				 const char *scenario)
{
	for (int i = 0; i < n; i++)
		if (!strcmp(rows[i].repr, repr) && (!scenario || !strcmp(rows[i].scenario, scenario)))
			return &rows[i];
	fail_msg("no row for %s on %s", repr, scenario ? scenario : "any scenario");
	return NULL;
}

void rfx_engine_grab(const struct irdm_image *img, const double p[3], const double *target,
		     size_t N, double *F)
{
	struct irdm_engine_config cfg;
	struct irdm_contact_site site;
	struct irdm_session *ses;

	irdm_engine_config_default(&cfg);
	cfg.max_contacts = 1;
	ses = efx_session(img, &cfg);
	assert_int_equal(irdm_engine_site_node(ses->eng, efx_column_row_near(img, p), &site), 0);
	for (size_t t = 0; t < N; t++) {
		struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];

		memset(cmd, 0, sizeof(cmd));
		if (!isnan(target[3 * t])) {
			if (irdm_engine_contact(ses->eng, 0)->mode == IRDM_CONTACT_OFF)
				assert_int_equal(irdm_engine_contact_begin(ses->eng, 0, &site, IRDM_CONTACT_GRAB), 0);
			cmd[0].mode = IRDM_CONTACT_GRAB;
			memcpy(cmd[0].target_m, &target[3 * t], sizeof(cmd[0].target_m));
		}
		assert_int_equal(irdm_engine_tick(ses->eng, cmd), 0);
		memcpy(&F[3 * t], irdm_engine_contact(ses->eng, 0)->force_n, 3 * sizeof(double));
	}
	irdm_session_close(ses);
}
