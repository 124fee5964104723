#include "world.h"

#include <math.h>
#include <string.h>

#include "alloc.h"
#include "applied.h"
#include "clock.h"
#include "cloth_group.h"
#include "collider_contacts.h"
#include "forces.h"
#include "implicit.h"
#include "integrate.h"
#include "parallel.h"
#include "selfcollide.h"
#include "status.h"
#include "step_guard.h"
#include "wetness.h"
#include "xpbd.h"

int32_t wc_version(void) { return WC_VERSION; }

const char *wc_version_string(void)
{
#define WC_STR2(x) #x
#define WC_STR(x) WC_STR2(x)
    return WC_STR(WC_VERSION_MAJOR) "." WC_STR(WC_VERSION_MINOR) "." WC_STR(WC_VERSION_PATCH);
}

int64_t wc_struct_size(const char *name)
{
    static const struct {
        const char *name;
        size_t size;
    } structs[] = {
        {"wc_message", sizeof(wc_message)},
        {"wc_world_def", sizeof(wc_world_def)},
        {"wc_material", sizeof(wc_material)},
        {"wc_mesh_cloth_def", sizeof(wc_mesh_cloth_def)},
        {"wc_grid_cloth_def", sizeof(wc_grid_cloth_def)},
        {"wc_cloth_view", sizeof(wc_cloth_view)},
        {"wc_energy", sizeof(wc_energy)},
        {"wc_mesh_collider_def", sizeof(wc_mesh_collider_def)},
        {"wc_convex_collider_def", sizeof(wc_convex_collider_def)},
        {"wc_step_stats", sizeof(wc_step_stats)},
        {"wc_intersection_counts", sizeof(wc_intersection_counts)},
    };
    if (!name) return 0;
    for (size_t k = 0; k < sizeof structs / sizeof structs[0]; ++k)
        if (!strcmp(name, structs[k].name)) return (int64_t)structs[k].size;
    return 0;
}

wc_world_def wc_world_def_default(void)
{
    wc_world_def d;
    memset(&d, 0, sizeof d);
    d.gravity[2] = -9.81;
    d.thread_count = 0;
    d.integrator = WC_INTEGRATOR_IMPLICIT;
    d.substep_safety = 0.9;
    d.max_substeps = 100000;
    d.implicit_tolerance = 8.0;
    d.adapt_threads = 1;
    return d;
}

static wc_status validate_world_def(const wc_world_def *d, wc_message *msg)
{
    for (int k = 0; k < 3; ++k)
        if (!isfinite(d->gravity[k]))
            return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                           "world_def.gravity[%d] must be finite but is %g", k, d->gravity[k]);
    if (d->thread_count < 0 || d->thread_count > 1024)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "world_def.thread_count must be in [0, 1024] (0 = OpenMP default) but is %d",
                       (int)d->thread_count);
    if (d->integrator != WC_INTEGRATOR_VERLET && d->integrator != WC_INTEGRATOR_XPBD &&
        d->integrator != WC_INTEGRATOR_IMPLICIT)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "world_def.integrator must be WC_INTEGRATOR_VERLET (0), "
                       "WC_INTEGRATOR_XPBD (1) or WC_INTEGRATOR_IMPLICIT (2) but is %d",
                       (int)d->integrator);
    if (!(d->substep_safety > 0.0 && d->substep_safety <= 1.0))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "world_def.substep_safety must be in (0, 1] but is %g", d->substep_safety);
    if (d->max_substeps < 1 || d->max_substeps > 10000000)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "world_def.max_substeps must be in [1, 10000000] but is %d",
                       (int)d->max_substeps);
    if (!(d->implicit_tolerance >= 0.0 && d->implicit_tolerance <= 1000.0))
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "world_def.implicit_tolerance must be in [0, 1000] m/s^2 but is %g",
                       d->implicit_tolerance);
    if (d->adapt_threads != 0 && d->adapt_threads != 1)
        return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                       "world_def.adapt_threads must be 0 or 1 but is %d", (int)d->adapt_threads);
    return WC_OK;
}

static void no_work(void *context, const wc_team *team)
{
    (void)context;
    (void)team;
}

/* The thread tuner's question, answered from the system's count. */
static double idle_cores_of(void *meter) { return wci_idle_meter_read(meter); }

wc_status wc_world_create(const wc_world_def *def, wc_world **out_world, wc_message *out_message)
{
    if (out_message) out_message->text[0] = '\0';
    if (!out_world)
        return wci_fail(out_message, WC_ERROR_INVALID_ARGUMENT, "wc_world_create: out_world is NULL");
    *out_world = NULL;
    if (!def)
        return wci_fail(out_message, WC_ERROR_INVALID_ARGUMENT, "wc_world_create: def is NULL");
    wc_status s = validate_world_def(def, out_message);
    if (s) return s;
    wc_world *w = wci_alloc_array(1, sizeof *w);
    if (!w) return wci_fail(out_message, WC_ERROR_OUT_OF_MEMORY, "out of memory creating a world");
    w->def = *def;
    w->tear_ratio = WC_TEAR_RATIO, w->tear_growth = WC_TEAR_GROWTH;
    wci_thread_tuner_create(&w->tuner, wci_thread_count(def->thread_count), def->adapt_threads);
    wci_idle_meter_start(&w->idle_meter);
    w->tuner.spare_cores = idle_cores_of;
    w->tuner.spare_context = &w->idle_meter;
    /* The threads are made now, not in the first step that probes more of
     * them: making them takes milliseconds, which that step's time would
     * count against them. */
    if (w->tuner.adapt) wci_parallel_team(w->tuner.most, no_work, NULL);
    *out_world = w;
    return WC_OK;
}

void wc_world_destroy(wc_world *w)
{
    if (!w) return;
    for (int32_t i = 0; i < w->cloth_count; ++i) wci_cloth_destroy(w->cloths[i]);
    for (int32_t i = 0; i < w->collider_count; ++i) wci_collider_destroy(w->colliders[i]);
    wci_free(w->cloths);
    wci_particles_free(&w->particles);
    wci_free(w->colliders);
    wci_contact_backup_destroy(&w->backup);
    wci_cloth_group_destroy(w->group);
    wci_free(w);
}

wc_message *wci_world_message(const wc_world *w) { return (wc_message *)&w->error; }

const char *wc_world_last_error(const wc_world *w) { return w ? w->error.text : "world is NULL"; }

wc_cloth *wci_world_find_cloth(const wc_world *w, int32_t cloth, const char *caller)
{
    if (cloth >= 0 && cloth < w->cloth_count) return w->cloths[cloth];
    wci_fail(wci_world_message(w), WC_ERROR_NOT_FOUND, "%s: cloth %d does not exist (the world has %d)",
            caller, (int)cloth, (int)w->cloth_count);
    return NULL;
}

/* ------------------------------------------------------------------------ */
/* Stepping                                                                  */
/* ------------------------------------------------------------------------ */

/* What the stages of one step share. The per-particle state they read and
 * write is the world's (particles.h), reached through each cloth's views;
 * only the commit moves those arrays. */
typedef struct step_context {
    /// Length of the step, s.
    double dt;
    /// Part of what is left of the advance that this step covers, and how
    /// many steps of it follow this one (colliders move by it).
    double share;
    int32_t steps_left;
    /// Fractions of the way to their targets the pins are at when the step
    /// starts and when it ends, and where the soft pins pull toward while
    /// forces are evaluated: the start, or the end for backward Euler.
    double pin_start, pin_fraction, goal_fraction;
    int threads;
    /// Whether the step has collisions at all (colliders, or a cloth that
    /// collides with itself or with others): then the commit applies the
    /// collision response's history overrides.
    int colliding;
} step_context;

static int any_cloth_collision(const wc_world *w)
{
    for (int32_t c = 0; c < w->cloth_count; ++c)
        if (w->cloths[c]->self) return 1;
    return wci_cloth_group_possible(w->cloths, w->cloth_count);
}

static wc_status non_finite_error(wc_world *w, double dt, int32_t cloth, int32_t particle,
                                  const char *phase)
{
    return wci_fail(&w->error, WC_ERROR_NON_FINITE,
                   "step of %g s would move particle %d of cloth %d to a non-finite position "
                   "(in %s); the stable step is about %g s. The world keeps its last good state",
                   dt, (int)particle, (int)cloth, phase, w->cloths[cloth]->stable_dt);
}

/* A Verlet step that makes a cloth oscillate with growing amplitude
 * (step_guard.h) fails before it is committed. The large-step integrators
 * are stable by construction; their tension-only links can chatter in a way
 * the guard would mistake for growth (measured: the implicit integrator on
 * a 1e9 N/m cloth, whose energy did not grow). */
static wc_status guard_steps(wc_world *w, double dt, int threads)
{
    if (w->def.integrator != WC_INTEGRATOR_VERLET) return WC_OK;
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        wc_cloth *cl = w->cloths[c];
        int32_t p = wci_step_guard_check(cl, &cl->guard, dt, threads, &cl->guard_next);
        if (p >= 0)
            return wci_fail(&w->error, WC_ERROR_NON_FINITE,
                           "step of %g s is unstable: particle %d of cloth %d oscillates with an "
                           "amplitude that grew %.3g-fold over the last %d steps (the stable step "
                           "is about %g s). The world keeps its last good state; take shorter "
                           "steps (wc_world_advance with 0 substeps picks them)",
                           dt, (int)p, (int)c, cl->guard_next.growth, (int)cl->guard_next.run,
                           cl->stable_dt);
    }
    return WC_OK;
}

/* What self-collision or the collision between cloths moved may now lie
 * against a collider feature the collider stage saw clear (a triangle pushed
 * down onto a proud vertex), so the collider stage runs again over it; what
 * that moves in turn is checked against the other layers (for a cloth of the
 * group, by wci_cloth_group_verify once every member is done), whose
 * fail-safe puts colliding pairs back where the step started, free of both. */
static wc_status recheck_colliders(wc_world *w, const step_context *ctx, int32_t c, int alone)
{
    wc_cloth *cl = w->cloths[c];
    int32_t moved = 0;
    const uint8_t *flags = NULL, *changed = NULL;
    if (!alone) flags = wci_cloth_group_moved(w->group, c, &moved);
    else if (cl->self) flags = wci_self_state_moved(cl->self, &moved);
    if (!moved || !cl->collider_contacts) return WC_OK;
    if (wci_collider_contacts_recheck(cl, cl->collider_contacts, w->colliders, w->collider_count,
                                      flags, ctx->steps_left, ctx->threads, &w->stats, &changed))
        return WC_ERROR_OUT_OF_MEMORY;
    if (!changed) return WC_OK;
    if (alone) return wci_self_verify(cl, changed, ctx->threads, &w->stats);
    memcpy(wci_cloth_group_flags(w->group, c), changed, (size_t)cl->particle_count);
    return WC_OK;
}

static wc_status between_cloths_failed(wc_world *w)
{
    return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                   "out of memory in the collision between cloths; the world keeps its last good "
                   "state");
}

/* Colliders move to where they are at the end of this step; each contact
 * then answers to the relative motion. `share` is the part of what is left
 * of the advance that this step covers, `steps_left` how many steps of it
 * follow this one. */
static wc_status collide(wc_world *w, const step_context *ctx)
{
    double dt = ctx->dt;
    int threads = ctx->threads;
    for (int32_t k = 0; k < w->collider_count; ++k)
        if (wci_collider_begin_step(w->colliders[k], ctx->share))
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                           "out of memory indexing collider %d; the world keeps its last good state",
                           (int)k);
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        wc_cloth *cl = w->cloths[c];
        /* this step's contacts replace the last step's, which wet friction
         * and the stuck test still need */
        memcpy(cl->contact_prev, cl->contact, (size_t)cl->particle_count);
        memset(cl->contact, 0, (size_t)cl->particle_count);
        memset(cl->history_override, 0, (size_t)cl->particle_count);
        cl->dt_step = dt;
        if (!w->collider_count) continue;
        if (!cl->collider_contacts && !(cl->collider_contacts = wci_collider_contacts_create(cl)))
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                           "out of memory for the collision buffers of cloth %d; the world "
                           "keeps its last good state", (int)c);
        if (wci_collider_contacts_resolve(cl, cl->collider_contacts, w->colliders, w->collider_count,
                                         ctx->steps_left, threads, &w->stats))
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                           "out of memory indexing cloth %d for collisions; the world keeps its "
                           "last good state", (int)c);
        /* before self-collision, which must see held particles as resting
         * on their collider */
        if (cl->wet_forces) wci_wet_hold_contacts(cl, w->colliders, w->collider_count, threads);
    }
    /* cloths against each other, after all their collider passes */
    if (wci_cloth_group_update(&w->group, w->cloths, w->cloth_count) ||
        (w->group && wci_cloth_group_collide(w->group, w->cloths, dt, threads, &w->stats)))
        return between_cloths_failed(w);
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        wc_cloth *cl = w->cloths[c];
        int alone = !wci_cloth_group_handled(w->group, c);
        if (alone && cl->self && wci_self_collide(cl, dt, threads, &w->stats))
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                           "out of memory in the self-collision of cloth %d; the world keeps its "
                           "last good state", (int)c);
        if (recheck_colliders(w, ctx, c, alone))
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                           "out of memory in the collisions of cloth %d; the world keeps its last "
                           "good state", (int)c);
    }
    if (w->group && wci_cloth_group_verify(w->group, w->cloths, threads, &w->stats))
        return between_cloths_failed(w);
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        wc_cloth *cl = w->cloths[c];
        int alone = !wci_cloth_group_handled(w->group, c);
        if (alone && cl->self && cl->wet_forces && wci_wet_self_pairs(cl, wci_self_thickness(cl)))
            return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                           "out of memory for the self-adhesion of cloth %d; the world keeps its "
                           "last good state", (int)c);
        long bad = -1;
        for (int axis = 0; axis < 3 && bad < 0; ++axis) {
            const double *v = axis == 0 ? cl->nx : axis == 1 ? cl->ny : cl->nz;
            bad = wci_first_non_finite(v, cl->particle_count);
        }
        if (bad >= 0) return non_finite_error(w, dt, c, (int32_t)bad, "collision response");
        /* counted once at the end: the passes above may visit a particle
         * more than once (self-collision counts its own contacts) */
        for (int32_t i = 0; i < cl->particle_count; ++i)
            w->stats.collider_contacts += cl->contact[i] == WC_CONTACT_COLLIDER;
    }
    return WC_OK;
}

/* Positions after the step into nx/ny/nz by the world's integrator; the
 * large-step integrators make their buffers at their first step. */
static wc_status integrate_cloth(wc_world *w, int32_t c, double dt, double pin_fraction,
                                 int threads)
{
    wc_cloth *cl = w->cloths[c];
    int32_t bad;
    switch (w->def.integrator) {
    case WC_INTEGRATOR_XPBD:
        if (!cl->xpbd && !(cl->xpbd = wci_xpbd_state_create(cl))) break;
        bad = wci_integrate_xpbd(cl, dt, pin_fraction, threads);
        return bad >= 0 ? non_finite_error(w, dt, c, bad, "integration") : WC_OK;
    case WC_INTEGRATOR_IMPLICIT:
        if (!cl->implicit && !(cl->implicit = wci_implicit_state_create(cl))) break;
        bad = wci_integrate_implicit(cl, dt, pin_fraction, w->def.implicit_tolerance, threads);
        w->solver_iterations += wci_implicit_last_iterations(cl->implicit);
        return bad >= 0 ? non_finite_error(w, dt, c, bad, "integration") : WC_OK;
    default:
        bad = wci_integrate_verlet(cl, dt, pin_fraction, threads);
        return bad >= 0 ? non_finite_error(w, dt, c, bad, "integration") : WC_OK;
    }
    return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                   "out of memory for the integrator buffers of cloth %d; the world keeps its "
                   "last good state", (int)c);
}

/* Forces, with the applied forces and the wet pull of the last step's
 * contacts, then the wet cloths sticking to each other (after every
 * cloth's own forces). */
static void forces_stage(wc_world *w, const step_context *ctx)
{
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        wc_cloth *cl = w->cloths[c];
        wci_forces_compute(cl, w->def.gravity, ctx->threads);
        if (wci_applied_active(cl)) wci_applied_forces_add(cl, ctx->goal_fraction, ctx->threads);
        if (cl->wet_forces) wci_wet_forces(cl, ctx->threads);
    }
    wci_cloth_group_adhesion(w->group, w->cloths);
}

/* Positions after the step into nx/ny/nz, then the unstable-step guard. */
static wc_status integrate_stage(wc_world *w, const step_context *ctx)
{
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        wc_status s = integrate_cloth(w, c, ctx->dt, ctx->pin_fraction, ctx->threads);
        if (s) return s;
    }
    return guard_steps(w, ctx->dt, ctx->threads);
}

/* Collisions with colliders, between cloths and of each cloth with itself
 * (wet friction acts in their response). They change contacts before they
 * know they will succeed: a failed step puts them back (contact_backup.h). */
static wc_status collide_stage(wc_world *w, const step_context *ctx)
{
    if (!ctx->colliding) return WC_OK;
    if (wci_contact_backup_save(&w->backup, w->cloths, w->cloth_count) ||
        wci_cloth_group_save(w->group))
        return wci_fail(&w->error, WC_ERROR_OUT_OF_MEMORY,
                       "out of memory saving the contact state; the world keeps its last "
                       "good state");
    wc_status s = collide(w, ctx);
    if (s) {
        wci_contact_backup_restore(&w->backup, w->cloths, w->cloth_count);
        wci_cloth_group_restore(w->group);
    }
    return s;
}

/* Whether the step's collisions would tear a cloth (step_guard.h). Without
 * collisions nothing is looked at: the tear comes from a contact's answer. */
static int step_tears(const wc_world *w, const step_context *ctx)
{
    if (!ctx->colliding) return 0;
    for (int32_t c = 0; c < w->cloth_count; ++c)
        if (wci_step_tears(w->cloths[c], w->tear_ratio, w->tear_growth, ctx->threads) >= 0) return 1;
    return 0;
}

/* A step refused after its collisions: their contact state put back, as a
 * failed step's is, so the half steps start from the world as it was. */
static void undo_collisions(wc_world *w, const step_context *ctx)
{
    if (!ctx->colliding) return;
    wci_contact_backup_restore(&w->backup, w->cloths, w->cloth_count);
    wci_cloth_group_restore(w->group);
}

/* The wet response (stuck particles), then the step's positions become the
 * current ones for every cloth at once. */
static void commit_stage(wc_world *w, const step_context *ctx)
{
    if (ctx->colliding)
        for (int32_t c = 0; c < w->cloth_count; ++c)
            w->stats.stuck_particles += wci_wet_mark_stuck(w->cloths[c]);
    wci_particles_commit(&w->particles, w->cloths, w->cloth_count);
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        wc_cloth *cl = w->cloths[c];
        if (cl->collider_contacts) wci_collider_contacts_commit(cl->collider_contacts, cl->particle_count);
        wci_cloth_commit(w->cloths[c], ctx->dt, ctx->colliding);
        w->cloths[c]->guard = w->cloths[c]->guard_next;
    }
    for (int32_t k = 0; k < w->collider_count; ++k) wci_collider_end_step(w->colliders[k]);
}

/* Wicking and drying. */
static void wetness_stage(wc_world *w, const step_context *ctx)
{
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        const wc_material *m = &w->cloths[c]->material;
        if (m->wicking > 0.0 || m->drying > 0.0) wci_wet_update(w->cloths[c], ctx->dt);
    }
}

/* One step of the whole world, as stages. Nothing is committed unless
 * every cloth's new state is finite, so a failed step leaves the world
 * exactly as it was. The pins are at pin_start of the way to their targets
 * when the step starts and at pin_fraction when it ends. */
static wc_status world_step(wc_world *w, double dt, double share, int32_t steps_left,
                            double pin_start, double pin_fraction, int may_refuse, int *refused)
{
    step_context ctx;
    ctx.dt = dt, ctx.share = share, ctx.steps_left = steps_left;
    ctx.pin_start = pin_start, ctx.pin_fraction = pin_fraction;
    ctx.goal_fraction = w->def.integrator == WC_INTEGRATOR_IMPLICIT ? pin_fraction : pin_start;
    ctx.threads = wci_thread_tuner_threads(&w->tuner);
    ctx.colliding = w->collider_count > 0 || any_cloth_collision(w);
    memset(&w->stats, 0, sizeof w->stats);
    w->stats.threads = ctx.threads;
    double *phase = w->phase_seconds, t0 = wci_clock_seconds(), t1;

    forces_stage(w, &ctx);
    t1 = wci_clock_seconds(), phase[0] += t1 - t0;
    /* a probe of fewer threads that has clearly lost by now runs the rest
     * of the step on the chosen count (thread_tuner.c) */
    ctx.threads = wci_thread_tuner_first_stage(&w->tuner, t1 - t0);
    w->stats.threads = ctx.threads;
    t0 = t1;

    wc_status s = integrate_stage(w, &ctx);
    if (s) return s;
    t1 = wci_clock_seconds(), phase[1] += t1 - t0, t0 = t1;

    s = collide_stage(w, &ctx);
    if (s) return s;
    t1 = wci_clock_seconds(), phase[2] += t1 - t0, t0 = t1;
    if (may_refuse && step_tears(w, &ctx)) {
        undo_collisions(w, &ctx);
        *refused = 1;
        return WC_OK;
    }

    commit_stage(w, &ctx);
    wetness_stage(w, &ctx);
    phase[3] += wci_clock_seconds() - t0;
    w->time += dt;
    return WC_OK;
}

/* A step, timed for the thread tuner: the next step's thread count comes
 * from how long this one took on its count. */
static wc_status timed_step(wc_world *w, double dt, double share, int32_t steps_left,
                            double pin_start, double pin_fraction, int may_refuse, int *refused)
{
    double start = wci_clock_seconds();
    wc_status s = world_step(w, dt, share, steps_left, pin_start, pin_fraction, may_refuse, refused);
    wci_thread_tuner_record(&w->tuner, wci_clock_seconds() - start);
    return s;
}

/* A step that would tear a cloth is taken again as two half steps, each of
 * them the same way, down to WC_TEAR_HALVINGS halvings (step_guard.h). The
 * first half covers half of the step's share of what is left of the
 * advance and of the pins' way; the second the rest. *reached becomes the
 * pins' fraction at the end of the last step that was committed. */
static wc_status refined_step(wc_world *w, double dt, double share, int32_t steps_left,
                              double pin_start, double pin_fraction, int halvings, double *reached)
{
    int refused = 0;
    wc_status s = timed_step(w, dt, share, steps_left, pin_start, pin_fraction,
                             halvings < WC_TEAR_HALVINGS, &refused);
    if (s) return s;
    if (!refused) {
        *reached = pin_fraction;
        return WC_OK;
    }
    ++w->halved_steps;
    double middle = 0.5 * (pin_start + pin_fraction), half = 0.5 * share;
    s = refined_step(w, 0.5 * dt, half, 2 * steps_left + 1, pin_start, middle, halvings + 1, reached);
    if (s) return s;
    return refined_step(w, 0.5 * dt, half / (1.0 - half), 2 * steps_left, middle, pin_fraction,
                        halvings + 1, reached);
}

/* Before a step or an advance: no phase time yet. */
static void start_timing(wc_world *w)
{
    memset(w->phase_seconds, 0, sizeof w->phase_seconds);
    w->solver_iterations = 0;
    w->halved_steps = 0;
}

/* After it: the phase times of all its steps into the stats. */
static void finish_timing(wc_world *w)
{
    w->stats.force_seconds = w->phase_seconds[0];
    w->stats.integrate_seconds = w->phase_seconds[1];
    w->stats.collide_seconds = w->phase_seconds[2];
    w->stats.wet_seconds = w->phase_seconds[3];
    w->stats.solver_iterations = w->solver_iterations;
    w->stats.halved_steps = w->halved_steps;
}

/* After an advance, pins start the next one from where they are: a hard
 * pin where its particle is, a soft pin where its target was at the end of
 * the last good step, `reached` of the way from `from` to `to` (a soft-
 * pinned particle is not on its target). A complete advance has brought
 * them to their targets; after a failed one they keep their targets, so the
 * next advance still takes them there. */
static void settle_pins(wc_world *w, double reached)
{
    for (int32_t c = 0; c < w->cloth_count; ++c) {
        wc_cloth *cl = w->cloths[c];
        for (int32_t p = 0; p < cl->pins.count; ++p) {
            int32_t i = cl->pins.particle[p];
            double *from = cl->pins.from + 3 * (size_t)p;
            if (cl->pins.stiffness && cl->pins.stiffness[p] > 0.0) {
                double target[3];
                wci_pinned_position(cl, p, reached, target);
                from[0] = target[0], from[1] = target[1], from[2] = target[2];
                continue;
            }
            from[0] = cl->x[i];
            from[1] = cl->y[i];
            from[2] = cl->z[i];
        }
    }
}

static wc_status check_step_length(wc_world *w, const char *name, double dt)
{
    if (!(isfinite(dt) && dt > 0.0 && dt <= 10.0))
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT, "%s must be in (0, 10] s but is %g",
                       name, dt);
    return WC_OK;
}

wc_status wc_world_step(wc_world *w, double dt)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_status s = check_step_length(w, "wc_world_step: dt", dt);
    if (s) return s;
    start_timing(w);
    double reached = 0.0;
    s = refined_step(w, dt, 1.0, 0, 0.0, 1.0, 0, &reached);
    finish_timing(w);
    settle_pins(w, reached);
    return s;
}

double wc_world_stable_dt(const wc_world *w)
{
    double dt = INFINITY;
    if (!w) return dt;
    for (int32_t c = 0; c < w->cloth_count; ++c)
        if (w->cloths[c]->stable_dt < dt) dt = w->cloths[c]->stable_dt;
    return dt;
}

wc_status wc_world_advance(wc_world *w, double frame_dt, int32_t substeps)
{
    if (!w) return WC_ERROR_INVALID_ARGUMENT;
    wc_status s = check_step_length(w, "wc_world_advance: frame_dt", frame_dt);
    if (s) return s;
    if (substeps < 0 || substeps > w->def.max_substeps)
        return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                       "wc_world_advance: substeps must be in [0, %d] (0 = automatic) but is %d",
                       (int)w->def.max_substeps, (int)substeps);
    if (substeps == 0) {
        double needed = ceil(frame_dt / (w->def.substep_safety * wc_world_stable_dt(w)));
        if (needed > w->def.max_substeps)
            return wci_fail(&w->error, WC_ERROR_INVALID_ARGUMENT,
                           "wc_world_advance: a frame of %g s needs %.0f substeps at the stable "
                           "step %g s, more than world_def.max_substeps = %d",
                           frame_dt, needed, wc_world_stable_dt(w), (int)w->def.max_substeps);
        substeps = needed < 1.0 ? 1 : (int32_t)needed;
    }
    double dt = frame_dt / substeps;
    start_timing(w);
    int32_t done = 0; /* substeps that succeeded */
    double reached = 0.0;
    while (done < substeps) {
        s = refined_step(w, dt, 1.0 / (substeps - done), substeps - done - 1,
                         (double)done / substeps, (double)(done + 1) / substeps, 0, &reached);
        if (s) break;
        ++done;
    }
    finish_timing(w);
    settle_pins(w, done == substeps ? 1.0 : reached);
    w->last_substeps = substeps;
    return s;
}

int32_t wc_world_last_substeps(const wc_world *w) { return w ? w->last_substeps : 0; }

double wc_world_time(const wc_world *w) { return w ? w->time : 0.0; }

int32_t wc_world_cloth_count(const wc_world *w) { return w ? w->cloth_count : 0; }

wc_step_stats wc_world_get_stats(const wc_world *w)
{
    wc_step_stats none;
    memset(&none, 0, sizeof none);
    return w ? w->stats : none;
}
