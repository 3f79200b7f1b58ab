/* SPDX-License-Identifier: MIT */
/* Forces by direct convolution of an image's responses (the reference). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image_response.h"
#include "irdm/error.h"
#include "modal/lapack.h"
#include "accuracy/reference.h"

/* The nodes of one contact: local column index and weight. */
struct site_nodes {
	unsigned n;
	unsigned l[3];
	double w[3];
};

struct conv_ws {
	const struct irdm_report_conv *c;
	size_t L; /* columns used */
	uint32_t col[IRDM_REPORT_MAX_COLS];
	size_t nr;                         /* rows of R */
	size_t rloc[IRDM_REPORT_MAX_COLS]; /* R row of column l */
	double *R;                         /* [nr][L][n_resp][9] */
	double *f;                         /* [N][L][3] node forces */
};

static const double *resp(const struct conv_ws *w, size_t r, size_t l, size_t s)
{
	return &w->R[((r * w->L + l) * w->c->n_resp + s) * 9];
}

/* Local index of image column col, added if new; -1 if full. */
static int local_col(struct conv_ws *w, uint32_t col)
{
	for (size_t l = 0; l < w->L; l++)
		if (w->col[l] == col)
			return (int)l;
	if (w->L == IRDM_REPORT_MAX_COLS)
		return -1;
	w->col[w->L] = col;
	return (int)w->L++;
}

static int site_of(struct conv_ws *w, const struct irdm_report_cmd *cmd, struct site_nodes *sn)
{
	const struct irdm_image *img = w->c->img;
	uint32_t rows[3];
	unsigned n = cmd->on_node ? 1 : 3;

	if (cmd->on_node)
		rows[0] = cmd->row;
	else
		for (unsigned k = 0; k < 3; k++)
			rows[k] = img->tris[3 * cmd->tri + k];
	sn->n = 0;
	for (unsigned k = 0; k < n; k++) {
		double wt = cmd->on_node ? 1.0 : cmd->bary[k];
		int64_t col = irdm_image_col_of(img, rows[k]);
		int l;

		if (wt == 0)
			continue;
		if (col < 0)
			return IRDM_ECONTACT;
		l = local_col(w, (uint32_t)col);
		if (l < 0)
			return IRDM_EINVAL;
		sn->l[sn->n] = (unsigned)l;
		sn->w[sn->n++] = wt;
	}
	return IRDM_OK;
}

/* Every column any tick's site uses; then the rows R is read for. */
static int collect(struct conv_ws *w, char *err, size_t errlen)
{
	const struct irdm_report_conv *c = w->c;
	struct site_nodes sn;

	for (size_t i = 0; i < c->N * c->m; i++) {
		int ret = site_of(w, &c->cmds[i], &sn);
		if (ret) {
			snprintf(err, errlen, "reference: tick %zu: %s", i / c->m,
				 ret == IRDM_EINVAL ? "the scenario touches too many columns" :
						      "a contact node is not touchable in the image");
			return ret;
		}
	}
	w->nr = c->disp_every ? c->img->meta->n_nodes : w->L;
	for (size_t l = 0; l < w->L; l++)
		w->rloc[l] = c->disp_every ? c->img->columns[w->col[l]] : l;
	return IRDM_OK;
}

static int read_responses(struct conv_ws *w, char *err, size_t errlen)
{
	const struct irdm_report_conv *c = w->c;

	w->R = malloc(w->nr * w->L * c->n_resp * 9 * sizeof(double));
	w->f = calloc(c->N * w->L * 3, sizeof(double));
	if (!w->R || !w->f)
		goto out_nomem;
	for (size_t r = 0; r < w->nr; r++)
		for (size_t l = 0; l < w->L; l++) {
			uint32_t row = c->disp_every ? (uint32_t)r : c->img->columns[w->col[r]];
			double *out = &w->R[(r * w->L + l) * c->n_resp * 9];

			if (irdm_image_response(c->img, w->col[l], row, c->n_resp, out))
				goto out_nomem;
		}
	return IRDM_OK;
out_nomem:
	snprintf(err, errlen, "reference: out of memory for %zu x %zu responses of %zu samples",
		 w->nr, w->L, c->n_resp);
	return IRDM_ENOMEM;
}

/* u[a] = sum_{s=s0}^{min(t, n_resp-1)} sum_l R[r,l,s] f[t-s][l]. */
static void convolve_row(const struct conv_ws *w, size_t r, size_t t, size_t s0, double u[3])
{
	size_t smax = t < w->c->n_resp - 1 ? t : w->c->n_resp - 1;

	u[0] = u[1] = u[2] = 0;
	for (size_t s = s0; s <= smax; s++)
		for (size_t l = 0; l < w->L; l++) {
			const double *R = resp(w, r, l, s), *f = &w->f[((t - s) * w->L + l) * 3];
			for (int a = 0; a < 3; a++)
				u[a] += R[3 * a] * f[0] + R[3 * a + 1] * f[1] + R[3 * a + 2] * f[2];
		}
}

/* One tick: solve the active contacts' forces, spread them to the nodes. */
static int tick(struct conv_ws *w, size_t t, double *F)
{
	const struct irdm_report_conv *c = w->c;
	struct site_nodes sn[IRDM_MAX_CONTACTS];
	unsigned act[IRDM_MAX_CONTACTS], na = 0;
	double A[36], b[6];
	int ipiv[6], n, one = 1, info;

	for (unsigned i = 0; i < c->m; i++) {
		const struct irdm_report_cmd *cmd = &c->cmds[t * c->m + i];
		F[3 * i] = F[3 * i + 1] = F[3 * i + 2] = 0;
		if (!cmd->active || na == 2)
			continue;
		site_of(w, cmd, &sn[na]);
		act[na++] = i;
	}
	if (!na)
		return IRDM_OK;
	n = 3 * (int)na;
	for (unsigned p = 0; p < na; p++) {
		const double *tg = c->cmds[t * c->m + act[p]].target_m;
		for (int a = 0; a < 3; a++)
			b[3 * p + a] = tg[a];
		for (unsigned v = 0; v < sn[p].n; v++) {
			double h[3];
			convolve_row(w, w->rloc[sn[p].l[v]], t, 1, h);
			for (int a = 0; a < 3; a++)
				b[3 * p + a] -= sn[p].w[v] * h[a];
		}
		for (unsigned q = 0; q < na; q++)
			for (int a = 0; a < 3; a++)
				for (int bb = 0; bb < 3; bb++) {
					double s = 0;
					for (unsigned v = 0; v < sn[p].n; v++)
						for (unsigned u = 0; u < sn[q].n; u++)
							s += sn[p].w[v] * sn[q].w[u] *
							     resp(w, w->rloc[sn[p].l[v]], sn[q].l[u], 0)[3 * a + bb];
					/* column-major for LAPACK */
					A[(3 * q + bb) * n + 3 * p + a] = s;
				}
	}
	dgesv_(&n, &one, A, &n, ipiv, b, &n, &info);
	if (info)
		return IRDM_ECONTACT;
	for (unsigned q = 0; q < na; q++)
		for (int a = 0; a < 3; a++) {
			F[3 * act[q] + a] = b[3 * q + a];
			for (unsigned u = 0; u < sn[q].n; u++)
				w->f[(t * w->L + sn[q].l[u]) * 3 + a] += sn[q].w[u] * b[3 * q + a];
		}
	return IRDM_OK;
}

int irdm_report_convolve(const struct irdm_report_conv *c, struct irdm_report_conv_out *out,
			 char *err, size_t errlen)
{
	struct conv_ws w = { .c = c };
	size_t n_nodes = c->img->meta->n_nodes;
	int ret;

	memset(out, 0, sizeof(*out));
	ret = collect(&w, err, errlen);
	if (ret)
		return ret;
	ret = read_responses(&w, err, errlen);
	if (ret)
		goto out_ws;
	out->n_eval = c->disp_every ? c->N / c->disp_every : 0;
	out->F = malloc(c->N * 3 * c->m * sizeof(double));
	out->disp = malloc((out->n_eval ? out->n_eval : 1) * n_nodes * 3 * sizeof(double));
	if (!out->F || !out->disp) {
		snprintf(err, errlen, "reference: out of memory");
		ret = IRDM_ENOMEM;
		goto out_free;
	}
	for (size_t t = 0; t < c->N; t++) {
		ret = tick(&w, t, &out->F[t * 3 * c->m]);
		if (ret) {
			snprintf(err, errlen, "reference: tick %zu: singular contact system", t);
			goto out_free;
		}
		if (c->disp_every && (t + 1) % c->disp_every == 0)
			for (size_t r = 0; r < n_nodes; r++)
				convolve_row(&w, r, t, 0, &out->disp[((t / c->disp_every) * n_nodes + r) * 3]);
	}
	goto out_ws;
out_free:
	irdm_report_conv_free(out);
out_ws:
	free(w.R);
	free(w.f);
	return ret;
}

void irdm_report_conv_free(struct irdm_report_conv_out *out)
{
	free(out->F);
	free(out->disp);
	memset(out, 0, sizeof(*out));
}
