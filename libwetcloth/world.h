#ifndef WC_WORLD_H
#define WC_WORLD_H

#include "cloth.h"
#include "collider.h"
#include "contact_backup.h"
#include "idle_cores.h"
#include "particles.h"
#include "thread_tuner.h"
#include "wetcloth.h"

struct wc_world {
    wc_world_def def;
    wc_cloth **cloths;
    int32_t cloth_count;
    int32_t cloth_capacity;
    /// The per-particle state of every cloth (particles.h).
    wc_particles particles;
    wc_collider **colliders;
    int32_t collider_count;
    int32_t collider_capacity;
    double time;
    int32_t last_substeps;
    wc_step_stats stats;
    /// Per-phase wall time summed over the running step or advance (the
    /// stats of each substep are cleared, these are not): forces,
    /// integration, collisions, wet response and commit.
    double phase_seconds[4];
    /// Linear-solver iterations since start_timing (world.c).
    int64_t solver_iterations;
    /// Steps taken again as halves since start_timing, and what tears
    /// (step_guard.h: WC_TEAR_RATIO and WC_TEAR_GROWTH; a test may set
    /// others to make every step be taken again).
    int32_t halved_steps;
    double tear_ratio, tear_growth;
    /// Message of the last failed call. Calls that take a const world still
    /// report here: the world itself is never const-defined (it comes from
    /// wc_world_create), so writing through a cast pointer is well defined.
    wc_message error;
    /// Contact state saved before each step's collision (contact_backup.h).
    wc_contact_backup backup;
    /// The cloths that collide with each other (cloth_group.h); NULL while
    /// fewer than two do.
    struct wc_cloth_group *group;
    /// How many threads the next step runs on (thread_tuner.h), and the
    /// machine's idle cores it asks for (idle_cores.h).
    wc_thread_tuner tuner;
    wc_idle_meter idle_meter;
};

/// The world's message buffer, writable from const entry points.
wc_message *wci_world_message(const wc_world *world);

/// The cloth at an index, or NULL after reporting WC_ERROR_NOT_FOUND.
wc_cloth *wci_world_find_cloth(const wc_world *world, int32_t cloth, const char *caller);

#endif
