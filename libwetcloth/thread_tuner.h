/* How many threads a world's next step runs on.
 *
 * Any thread count gives the same bits (every loop writes each output from
 * one iteration, and sums run in fixed blocks), so the count is free to
 * change from step to step, and the world picks it by measuring. More
 * threads are not always faster: when another program keeps a core busy, a
 * thread the scheduler takes away holds every barrier of the step until it
 * runs again (a scheduler tick, milliseconds), and a small cloth's loops
 * are shorter than waking the team. So the tuner times each step, and now
 * and then spends a few steps on a neighbouring count (half or twice the
 * chosen one, within [1, most]); it keeps whichever is faster. A world
 * starts on one thread; a count that keeps winning is probed less and less
 * often, a count that lost by much is probed rarely (its probes are dear),
 * and several threads that suddenly take much longer (the machine got
 * busier) are probed against fewer at once. A probe of more threads is
 * not run while the system says that the cores they would need are busy
 * (idle_cores.h), and a probe of fewer threads that has clearly lost by the
 * end of a step's first stage ends there, the rest of the step on the
 * chosen count.
 * thread_tuner.c has the rules and why.
 *
 * The tuner is a state machine fed with durations, so tests drive it with
 * made-up timings. */
#ifndef WC_THREAD_TUNER_H
#define WC_THREAD_TUNER_H

#include <stdint.h>

/// Steps of the chosen count whose median tells a slowdown.
#define WC_TUNER_SAMPLES 3
/// Steps of one probe: the chosen and the probed count in turn.
#define WC_TUNER_PROBE_STEPS 8

typedef struct wc_thread_tuner {
    /// The most threads the world may use.
    int32_t most;
    /// 0: always `most` (the world's adapt_threads off).
    int32_t adapt;
    /// The count chosen, the count being probed (0 when none), and the
    /// count of the next step.
    int32_t chosen;
    int32_t probed;
    int32_t current;
    /// Steps at the chosen count before the next probe, and between
    /// probes now (doubled each time the chosen count wins).
    int32_t until_probe;
    int32_t period;
    /// Direction of the next probe: -1 fewer threads, +1 more.
    int32_t direction;
    /// Steps still to skip before timing (the first steps allocate buffers).
    int32_t warmup;
    /// The chosen count's latest step times (a ring), how many are in it,
    /// and their median when the count was last compared.
    double recent[WC_TUNER_SAMPLES];
    int32_t recent_count;
    int32_t recent_next;
    double reference;
    /// The running probe: its step, and each block's time on either count.
    int32_t probe_step;
    double block_chosen[2];
    double block_probed[2];
    /// The running probe's first-stage times on the chosen count: their
    /// sum and how many (probes of fewer threads).
    double stage_chosen;
    int32_t stage_chosen_steps;
    /// 1 while a step runs whose probe ended after its first stage: that
    /// step's time, half on either count, is no sample.
    int32_t skip_record;
    /// How many cores sat idle since it was last asked, asked before a
    /// probe of more threads: >= 0, or WC_IDLE_UNKNOWN (the probe runs) or
    /// WC_IDLE_TOO_SOON (it waits FIRST_PROBE steps); NULL: never asked.
    /// The world reads the system's count (idle_cores.h), tests make one up.
    double (*spare_cores)(void *context);
    void *spare_context;
} wc_thread_tuner;

/// Starts a tuner for up to `most` threads (>= 1), adapting when `adapt`.
void wci_thread_tuner_create(wc_thread_tuner *tuner, int32_t most, int32_t adapt);

/// Threads for the next step.
int32_t wci_thread_tuner_threads(const wc_thread_tuner *tuner);

/// Records how long the step's first stage (the forces) took on
/// wci_thread_tuner_threads() threads (seconds), and returns the count for
/// the rest of the step: the chosen one when a probe of fewer threads has
/// already clearly lost.
int32_t wci_thread_tuner_first_stage(wc_thread_tuner *tuner, double seconds);

/// Records how long the step just taken, on wci_thread_tuner_threads()
/// threads, took (seconds), and picks the count of the next one.
void wci_thread_tuner_record(wc_thread_tuner *tuner, double seconds);

#endif
