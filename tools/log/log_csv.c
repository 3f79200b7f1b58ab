/* SPDX-License-Identifier: MIT */
/*
 * Telemetry log -> CSV.  Doubles are printed with 17 significant digits,
 * so every value reads back bit for bit (the test compares them so).
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "irdm/posix/outfile.h"
#include "irdm/posix/telemetry_log.h"
#include "irdm/telemetry.h"
#include "log/log_csv.h"

const char irdm_log_csv_columns_help[] =
	"columns (units in the names; devices d0, d1 as the log's header says):\n"
	"  tick             tick number since the loop started\n"
	"  t_s              tick * period (s)\n"
	"  wake_latency_ns  wake-up time minus the deadline\n"
	"  compute_ns       the tick's work, wake-up to torque written\n"
	"  state            init, ready, enabled, fault or off\n"
	"  fault_flags      the fault bit set as a number: 1 clamp, 2 workspace,\n"
	"                   4 velocity, 8 watchdog, 16 overrun, 32 encoder_nan,\n"
	"                   64 encoder_range, 128 signal, 256 hal_read,\n"
	"                   512 hal_write, 1024 hal_fault, 2048 engine\n"
	"  faults           the same bits by name, joined by '|' (empty: none)\n"
	"  dN_x_m dN_y_m dN_z_m            tip position (object frame)\n"
	"  dN_vx_m_s dN_vy_m_s dN_vz_m_s   tip velocity (estimated)\n"
	"  dN_q1_rad dN_q2_rad dN_q3_rad   joint angles\n"
	"  dN_tau1_nm dN_tau2_nm dN_tau3_nm  joint torques commanded\n"
	"  dN_fx_n dN_fy_n dN_fz_n         force on the object (the device renders its negative)\n"
	"  dN_proxy         free, touch, slide or release\n"
	"  dN_tri           the proxy's surface triangle, -1 if none\n"
	"  dN_site_tri      the engine's contact site this tick: surface triangle,\n"
	"                   -1 if no contact was commanded\n"
	"  dN_b0 dN_b1 dN_b2                its barycentrics\n"
	"  dN_tx_m dN_ty_m dN_tz_m          the engine's target: tip less the site's rest point\n";

static const char *const vec_cols[5][3] = {
	{ "x_m", "y_m", "z_m" },
	{ "vx_m_s", "vy_m_s", "vz_m_s" },
	{ "q1_rad", "q2_rad", "q3_rad" },
	{ "tau1_nm", "tau2_nm", "tau3_nm" },
	{ "fx_n", "fy_n", "fz_n" },
};

static void write_header_row(FILE *f, unsigned n_devices)
{
	fputs("tick,t_s,wake_latency_ns,compute_ns,state,fault_flags,faults", f);
	for (unsigned d = 0; d < n_devices; d++) {
		for (int v = 0; v < 5; v++)
			for (int k = 0; k < 3; k++)
				fprintf(f, ",d%u_%s", d, vec_cols[v][k]);
		fprintf(f, ",d%u_proxy,d%u_tri,d%u_site_tri,d%u_b0,d%u_b1,d%u_b2,d%u_tx_m,d%u_ty_m,"
			   "d%u_tz_m",
			d, d, d, d, d, d, d, d, d);
	}
	fputc('\n', f);
}

static void write_faults(FILE *f, uint32_t flags)
{
	const char *sep = "";

	for (unsigned b = 0; b < 32; b++) {
		if (!(flags & (1u << b)))
			continue;
		if (b < IRDM_TELEM_N_FAULTS)
			fprintf(f, "%s%s", sep, irdm_telem_fault_name(b));
		else
			fprintf(f, "%sbit%u", sep, b);
		sep = "|";
	}
}

static void write_device(FILE *f, const struct irdm_tick_dev *d)
{
	const double *vec[5] = { d->tip_pos_m, d->tip_vel_m_s, d->joint_angle_rad,
				 d->joint_torque_nm, d->force_n };

	for (int v = 0; v < 5; v++)
		for (int k = 0; k < 3; k++)
			fprintf(f, ",%.17g", vec[v][k]);
	fprintf(f, ",%s,", irdm_telem_proxy_name(d->proxy));
	if (d->contact_tri == IRDM_TELEM_NO_TRI)
		fputs("-1", f);
	else
		fprintf(f, "%u", d->contact_tri);
	if (d->site_tri == IRDM_TELEM_NO_TRI)
		fputs(",-1", f);
	else
		fprintf(f, ",%u", d->site_tri);
	for (int k = 0; k < 3; k++)
		fprintf(f, ",%.17g", d->site_bary[k]);
	for (int k = 0; k < 3; k++)
		fprintf(f, ",%.17g", d->target_m[k]);
}

static void write_row(FILE *f, const struct irdm_tick_record *r, const struct irdm_log_header *h)
{
	/* t = tick * period, printed exactly from integer microseconds */
	unsigned long long us = (unsigned long long)r->tick * h->period_us;

	fprintf(f, "%llu,%llu.%06llu,%d,%u,%s,%u,", (unsigned long long)r->tick, us / 1000000,
		us % 1000000, r->wake_latency_ns, r->compute_ns, irdm_telem_state_name(r->state),
		r->fault_flags);
	write_faults(f, r->fault_flags);
	for (unsigned d = 0; d < h->n_devices; d++)
		write_device(f, &r->dev[d]);
	fputc('\n', f);
}

/* Every record of r to f; returns IRDM_OK or the reader's error. */
static int write_rows(struct irdm_log_reader *r, FILE *f, char *err, size_t errlen)
{
	const struct irdm_log_header *h = irdm_log_header(r);
	struct irdm_tick_record rec;
	int got;

	write_header_row(f, h->n_devices);
	while ((got = irdm_log_next(r, &rec, err, errlen)) == 1)
		write_row(f, &rec, h);
	return got;
}

int irdm_log_export_csv(const char *log_path, const char *csv_path, char *err, size_t errlen)
{
	struct irdm_log_reader *r;
	struct irdm_outfile o;
	int ret;

	ret = irdm_log_open(&r, log_path, err, errlen);
	if (ret)
		return ret;
	ret = irdm_outfile_open(&o, csv_path, err, errlen);
	if (ret)
		goto out_close;
	/* a damaged block stops the rows: the CSV is then not written at all */
	ret = write_rows(r, o.f, err, errlen);
	if (ret)
		irdm_outfile_abort(&o);
	else
		ret = irdm_outfile_commit(&o, err, errlen);
out_close:
	irdm_log_close(r);
	return ret;
}
