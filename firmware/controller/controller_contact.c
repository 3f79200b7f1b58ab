/* SPDX-License-Identifier: MIT */
/*
 * Step 6 of the tick: one proxy per device on the DEFORMED surface (the
 * engine's free response, irdm_engine_node_disp(): the surface a contact
 * meets this tick), its site handed to the engine every tick (sliding keeps
 * the contact's past; the R[0] table is refreshed only when the site's
 * nodes change), the target p_obj - the site's rest point, and one engine
 * tick.  A device leaving the surface ends its push.  Device i drives
 * engine slot i.
 *
 * The closest-point query grows every BVH box by a bound on |u|: the
 * configured worst case (5 cm by default) made a free tick visit most of
 * the surface.  The engine's per-tick bound (irdm_engine_disp_bound(), a
 * true bound) shrinks it to the device's neighbourhood; the answer is the
 * same wherever the configured bound held, since both are valid bounds.
 */
#include <math.h>
#include <string.h>

#include "controller_priv.h"
#include "irdm/vec3.h"

/* Added to the engine's bound: BVH boxes are floats, the nodes' rest
 * positions too; 1 um is far above their rounding and far below a box. */
#define DISP_MARGIN_M 1e-6

static void node_disp(const void *ctx, uint32_t row, double u_m[3])
{
	const struct irdm_ctrl *c = ctx;
	struct irdm_ctrl_disp_cache *m = (struct irdm_ctrl_disp_cache *)&c->disp;
	uint32_t k = row % IRDM_CTRL_DISP_CACHE;

	if (m->filled[k] != m->stamp || m->row[k] != row) {
		irdm_engine_node_disp(c->s->eng, row, m->u_m[k]);
		m->row[k] = row;
		m->filled[k] = m->stamp;
	}
	memcpy(u_m, m->u_m[k], sizeof(m->u_m[k]));
}

/* This tick's proxy configuration: max_disp_m from the engine's state,
 * needed (O(modes)) only by a proxy that is not active: its query. */
static void proxy_cfg(const struct irdm_ctrl *c, struct irdm_proxy_config *pc)
{
	*pc = c->cfg.proxy;
	for (unsigned i = 0; i < c->cfg.n_devices; i++)
		if (!c->dev[i].px.active) {
			pc->max_disp_m = fmin(pc->max_disp_m,
					      irdm_engine_disp_bound(c->s->eng) + DISP_MARGIN_M);
			return;
		}
}

/* The proxy, out in the world frame (it lives in the object's own). */
static void proxy_out(const struct irdm_ctrl *c, const struct irdm_proxy *px,
		      struct irdm_ctrl_device_output *o)
{
	double tip_m[3], tip_w[3];

	o->tri = px->tri;
	memcpy(o->bary, px->bary, sizeof(o->bary));
	irdm_engine_object_to_world(c->s->eng, px->point_m, o->proxy_m);
	irdm_v3_add(tip_m, px->point_m, px->normal);
	irdm_engine_object_to_world(c->s->eng, tip_m, tip_w);
	irdm_v3_sub(o->normal, tip_w, o->proxy_m);
	o->depth_m = px->depth_m;
}

/*
 * A touch deeper than the tip can travel in one period at the speed limit
 * did not come from outside: the tool was already inside (at enable, out of
 * a fault, or rising into the detection radius from within).  Such a
 * contact engages softly (irdm_engine_contact_soften()): from zero force,
 * the full coupling after the engine's fade, instead of the spring's whole
 * depth in one tick.
 */
static bool began_inside(const struct irdm_ctrl *c, const struct irdm_proxy *px)
{
	return -px->depth_m > c->cfg.limits.max_tip_speed_m_per_s * c->cfg.period_us * 1e-6;
}

/* Device i's proxy and engine command.  Return: IRDM_OK; IRDM_EFAULT. */
static int touch(struct irdm_ctrl *c, unsigned i, const struct irdm_proxy_config *pc,
		 struct irdm_ctrl_device_output *o)
{
	const struct irdm_contact_disp disp = { .fn = node_disp, .ctx = c };
	struct irdm_ctrl_dev *d = &c->dev[i];
	struct irdm_contact_site site;
	double tip_own_m[3];
	bool fresh;
	int ev;

	/* the proxy on the object as it is now: a floating one has moved */
	irdm_engine_world_to_object(c->s->eng, o->tip_obj_m, tip_own_m);
	ev = irdm_proxy_update(&d->px, &c->cm, &disp, pc, tip_own_m);
	if (ev < 0)
		return IRDM_EFAULT;
	o->proxy_event = ev;
	if (ev != IRDM_PROXY_TOUCH && ev != IRDM_PROXY_SLIDE)
		return IRDM_OK; /* FREE, or RELEASE: the command stays OFF */
	proxy_out(c, &d->px, o);
	fresh = irdm_engine_contact(c->s->eng, i)->mode == IRDM_CONTACT_OFF;
	if (irdm_proxy_site(&d->px, &c->cm, &site) ||
	    irdm_engine_contact_begin(c->s->eng, i, &site, IRDM_CONTACT_PUSH))
		return IRDM_EFAULT;
	/* a contact the engine starts afresh: a touch, or a slide whose
	 * contact the push release ended (a soft start's first force is zero
	 * to rounding, and may be taken for a pull) */
	o->softened = fresh && began_inside(c, &d->px);
	if (o->softened && irdm_engine_contact_soften(c->s->eng, i))
		return IRDM_EFAULT;
	d->cmd.mode = IRDM_CONTACT_PUSH;
	irdm_v3_sub(d->cmd.target_m, o->tip_obj_m, site.rest_m);
	memcpy(o->target_m, d->cmd.target_m, sizeof(o->target_m));
	return IRDM_OK;
}

/* The engine's force, in the proxy's frame (a floating object's own), for
 * friction's next judgement (irdm_proxy_force()). */
static void proxy_force(const struct irdm_ctrl *c, struct irdm_proxy *px, const double f[3])
{
	double zero[3] = { 0, 0, 0 }, o[3], fo[3];

	irdm_engine_world_to_object(c->s->eng, zero, o);
	irdm_engine_world_to_object(c->s->eng, f, fo);
	irdm_v3_sub(fo, fo, o);
	irdm_proxy_force(px, fo);
}

void ctrl_contacts_end(struct irdm_ctrl *c)
{
	for (unsigned i = 0; i < c->cfg.n_devices; i++) {
		irdm_proxy_reset(&c->dev[i].px);
		irdm_engine_contact_end(c->s->eng, i);
		memset(&c->dev[i].cmd, 0, sizeof(c->dev[i].cmd));
	}
}

int ctrl_contacts(struct irdm_ctrl *c, struct irdm_ctrl_output *out, bool on)
{
	struct irdm_contact_cmd cmd[IRDM_MAX_CONTACTS];
	struct irdm_proxy_config pc;

	memset(cmd, 0, sizeof(cmd));
	c->disp.stamp++; /* the engine ticked since: every memo is stale */
	proxy_cfg(c, &pc);
	for (unsigned i = 0; i < c->cfg.n_devices; i++) {
		struct irdm_ctrl_device_output *o = &out->dev[i];

		memset(&c->dev[i].cmd, 0, sizeof(c->dev[i].cmd));
		if (on && c->dev[i].pose_ok && touch(c, i, &pc, o))
			return IRDM_EFAULT;
		cmd[i] = c->dev[i].cmd;
	}
	if (irdm_engine_tick(c->s->eng, cmd))
		return IRDM_EFAULT;
	for (unsigned i = 0; i < c->cfg.n_devices; i++) {
		const struct irdm_contact_state *st = irdm_engine_contact(c->s->eng, i);

		out->dev[i].contact = st->mode != IRDM_CONTACT_OFF;
		memcpy(out->dev[i].force_obj_n, st->force_n, sizeof(st->force_n));
		proxy_force(c, &c->dev[i].px, st->force_n);
	}
	return IRDM_OK;
}
