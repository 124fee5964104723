/* OpenMP settings shared by the per-step loops. Every parallel loop writes
 * each output element from exactly one iteration, so results never depend on
 * the thread count. */
#ifndef WC_PARALLEL_H
#define WC_PARALLEL_H

#include <stdint.h>

/// Loops with fewer iterations than this run on one thread: below it, waking
/// the thread team costs about what the loop itself does. At 4096 every
/// loop of a cloth of a few thousand particles ran on one thread, and 2
/// threads gained 3-7 % per frame; from 512 the 25 x 25 to 50 x 50 cloths on
/// the 3,968-triangle sphere (576 to 2,500 particles) take 1.18-1.57 times
/// less time per frame on 2 threads, and the 400-particle thesis drape no
/// more (docs/model.md, Cost of a step: measured with
/// `build/tools/bench_contacts scene=sphere64 size=N threads=1|2 adapt=0`).
#define WC_PARALLEL_MIN 512

/// Threads to use for a world's thread_count setting (0 = OpenMP default).
int wci_thread_count(int requested);

/// Threads a loop of `work` iterations runs on: `threads` from
/// WC_PARALLEL_MIN iterations up, one below.
static inline int wc_threads_for(int64_t work, int threads)
{
    return work >= WC_PARALLEL_MIN ? threads : 1;
}

/// The body of a loop over the items [begin, end); returns nonzero to flag
/// something (a non-finite value, say), which wci_parallel_for passes on.
typedef int (*wc_range_fn)(void *context, int64_t begin, int64_t end);

/// Runs body over the items [0, n): with threads > 1, in one contiguous
/// slice per thread (as schedule(static)); with one thread, by a plain call.
/// Returns 1 when any call of body returned nonzero, else 0.
/// Why not `#pragma omp parallel for if (...)`: libgomp enters a region
/// even when its if clause is false, and leaving it wakes the team with a
/// futex system call: ~0.4 us per loop measured here, more than most loops
/// of a 400-particle cloth cost, and a step runs several of them.
int wci_parallel_for(int64_t n, int threads, wc_range_fn body, void *context);

/// One thread of a team that runs a whole sequence of loops in one parallel
/// region (wci_parallel_team): its number, from 0, and the team's size.
typedef struct wc_team {
    int thread, threads;
} wc_team;

typedef void (*wc_team_fn)(void *context, const wc_team *team);

/// Runs body once on each thread of a team of `threads`: with threads > 1
/// inside one parallel region, with one by a plain call (team {0, 1}).
/// Why: a solver iteration runs a dozen dependent loops, and a region per
/// loop pays the team's wake-up and a join for each; a thread the scheduler
/// takes away holds every one of them. In one region the loops are
/// separated by barriers (wci_team_barrier), only where a loop reads what
/// another thread wrote.
void wci_parallel_team(int threads, wc_team_fn body, void *context);

/// Waits until every thread of the team has reached it; nothing for a
/// team of one.
void wci_team_barrier(const wc_team *team);

/// This thread's part [*begin, *end) of the items [0, n): with `split`, the
/// contiguous slice wci_parallel_for would give it; without, all of them on
/// the team's first thread and none on the others.
static inline void wc_team_slice(const wc_team *team, int64_t n, int split, int64_t *begin,
                                 int64_t *end)
{
    if (split) {
        *begin = n * team->thread / team->threads;
        *end = n * (team->thread + 1) / team->threads;
    } else {
        *begin = 0;
        *end = team->thread == 0 ? n : 0;
    }
}

#endif
