#include "thread_tuner.h"

#include <stddef.h>

#include "idle_cores.h"

#include "invariant.h"
#include "vec3.h"

/* A world starts on one thread and first tries more after FIRST_PROBE
 * steps: on a busy machine a step on more threads can take many times
 * longer (15x was measured here, at 4 runnable processes on 2 cores, and
 * tens of times for a 961-particle drape with one core busy), and a start on one
 * costs an idle machine only those first steps at its single-thread speed.
 * The first probe comes early because a probe that is clearly lost ends
 * after one step (ABANDON): on a busy machine it costs that one step
 * whenever it comes, and on an idle one the steps before it run on one
 * thread (with 32, a quarter of a 12-frame run at 12 steps per frame).
 * Probes then come every FIRST_PERIOD steps, backing
 * off to BACKOFF_PERIOD while the chosen count keeps winning (so a machine
 * that becomes free again is used within that many steps), and never more
 * often than keeps a lost probe's cost (its 4 steps on the slower count)
 * to about PROBE_COST of the steps between probes, up to MAX_PERIOD. */
#define FIRST_PROBE 8
#define FIRST_PERIOD 32
#define BACKOFF_PERIOD 1024
#define MAX_PERIOD 4096
#define PROBE_COST 0.05
/* A chosen count of several threads whose steps take this much longer
 * than when it was last compared is probed against fewer at once (the
 * machine got busier). A single thread that gets slower is left alone:
 * more threads would only be slower still. */
#define SLOWDOWN 1.5
/* More threads must be this much faster to be taken (they cost the rest of
 * the machine more); fewer are taken when they are no slower. */
#define MORE_THREADS_GAIN 0.97
/* A probed count's step that takes more than this many times the chosen
 * count's steps of the same probe ends the probe at once, lost: it cannot
 * win (it must be faster in both halves), and on a machine with a core
 * busy one step on two threads took tens of times one on one thread (a
 * 961-particle drape at 12 steps per frame: the frame that held a whole
 * 4-step probe took 65-80 ms against 5.5-6, one that ends it after its
 * first step 46-49). */
#define ABANDON 2.0
/* Sooner still: a probe of fewer threads whose step's first stage (the
 * forces, the first loops that split over the threads) took more than
 * EARLY_ABANDON times the chosen count's runs the rest of that step on the
 * chosen count, and the probe ends, lost. On an idle machine the
 * 10,201-particle drape's forces took 1.3-2.7 times as long on 1 thread as
 * on 2, and a probe of 1 thread ran 4 steps on it (in contact about 13 ms
 * more each). Only probes of fewer threads: their threads ran the last
 * step too, while a probe of more starts threads whose caches are cold,
 * and its first step's forces took 1.6-1.9 times one thread's on an idle
 * machine, where later steps take 0.6-0.8 times (design-notes.md). Only
 * stages of at least EARLY_MIN_SECONDS on the chosen count are compared:
 * a cloth whose forces are shorter (a few hundred particles: its loops
 * barely split, or not at all below WC_PARALLEL_MIN) says nothing about
 * the count there. */
#define EARLY_ABANDON 1.25
#define EARLY_MIN_SECONDS 5e-4
/* Cheaper than any lost probe is one not run: a probe of more threads
 * needs, since the last time the tuner asked, at least SPARE_PER_THREAD
 * idle cores per thread it adds (the system's count, idle_cores.h). With
 * another program keeping the second of 2 cores busy the count was 0.0-0.1
 * cores, idle 0.9-1.0; a probe that could win needs the cores, and one that
 * cannot cost up to a whole step at several times a step's time (the
 * 10,201-particle drape: 5x). Skipped, it counts as lost at no cost: the
 * period doubles as for a lost probe (so a machine that becomes free is
 * used within BACKOFF_PERIOD steps). Where the count is unknown, probes
 * run as they would without it. */
#define SPARE_PER_THREAD 0.5

/* A probe runs the chosen count (A) and the probed one (B) in the order
 * A B B A, twice: within each block both get the same sum of step
 * positions, so a cost that rises or falls steadily over the probe (a
 * cloth coming into contact) favours neither. The probed count wins only
 * when it wins both blocks. */
static const int32_t PROBE_ORDER[WC_TUNER_PROBE_STEPS] = {0, 1, 1, 0, 0, 1, 1, 0};

static double median3(const double *t)
{
    return max2(min2(t[0], t[1]), min2(max2(t[0], t[1]), t[2]));
}

void wci_thread_tuner_create(wc_thread_tuner *t, int32_t most, int32_t adapt)
{
    t->most = most < 1 ? 1 : most;
    t->adapt = adapt && t->most > 1;
    t->chosen = t->current = t->adapt ? 1 : t->most;
    t->probed = 0;
    t->period = FIRST_PERIOD;
    t->until_probe = FIRST_PROBE;
    t->direction = 1;
    t->warmup = 2;
    t->recent_count = t->recent_next = t->probe_step = 0;
    t->reference = 0.0;
    t->stage_chosen = 0.0;
    t->stage_chosen_steps = t->skip_record = 0;
    t->spare_cores = NULL;
    t->spare_context = NULL;
}

int32_t wci_thread_tuner_threads(const wc_thread_tuner *t) { return t->current; }

/* The neighbouring count of the chosen one that way, or 0 when there is
 * none. */
static int32_t neighbour(const wc_thread_tuner *t, int32_t direction)
{
    if (direction < 0) return t->chosen > 1 ? t->chosen / 2 : 0;
    if (t->chosen >= t->most) return 0;
    return 2 * t->chosen < t->most ? 2 * t->chosen : t->most;
}

/* After a lost probe: the next one comes after twice the period (up to
 * BACKOFF_PERIOD), or later still when this one cost much, so that lost
 * probes cost about PROBE_COST of the time; `extra` is what the probed
 * count's steps took beyond the chosen count's, in chosen-count steps. */
static void back_off(wc_thread_tuner *t, double extra)
{
    double wait = extra / PROBE_COST;
    int32_t period = 2 * t->period < BACKOFF_PERIOD ? 2 * t->period : BACKOFF_PERIOD;
    if (wait > period) period = wait < MAX_PERIOD ? (int32_t)wait : MAX_PERIOD;
    t->period = period;
}

static void start_probe(wc_thread_tuner *t)
{
    int32_t next = neighbour(t, t->direction);
    if (!next) {
        t->direction = -t->direction;
        next = neighbour(t, t->direction);
    }
    double spare = next > t->chosen && t->spare_cores ? t->spare_cores(t->spare_context)
                                                      : WC_IDLE_UNKNOWN;
    if (spare == WC_IDLE_TOO_SOON) {
        t->until_probe = FIRST_PROBE;
        return;
    }
    t->direction = -t->direction; /* alternate, so both ways get tried */
    if (spare >= 0.0 && spare < SPARE_PER_THREAD * (next - t->chosen)) {
        /* the cores it needs are busy: lost, at no cost */
        back_off(t, 0.0);
        t->until_probe = t->period;
        return;
    }
    t->probed = next;
    t->probe_step = 0;
    for (int k = 0; k < 2; ++k) t->block_chosen[k] = t->block_probed[k] = 0.0;
    t->stage_chosen = 0.0;
    t->stage_chosen_steps = 0;
    t->current = t->chosen; /* PROBE_ORDER[0] */
}

static void finish_probe(wc_thread_tuner *t)
{
    t->probed = 0;
    t->current = t->chosen;
    t->until_probe = t->period;
}

static void end_probe(wc_thread_tuner *t)
{
    double gain = t->probed < t->chosen ? 1.0 : MORE_THREADS_GAIN;
    int won = 1;
    for (int k = 0; k < 2; ++k) won &= t->block_probed[k] <= gain * t->block_chosen[k];
    if (won) {
        t->chosen = t->probed;
        t->reference = 0.0;
        t->recent_count = t->recent_next = 0;
        t->period = FIRST_PERIOD;
    } else {
        /* the probed count's extra time, in chosen-count steps (half the
         * probe's steps were on each count) */
        double chosen = t->block_chosen[0] + t->block_chosen[1];
        double probed = t->block_probed[0] + t->block_probed[1];
        double steps = 0.5 * WC_TUNER_PROBE_STEPS;
        back_off(t, chosen > 0.0 ? steps * (probed / chosen - 1.0) : 0.0);
    }
    finish_probe(t);
}

/* The mean time of the probe's steps on the chosen count so far. */
static double chosen_step_time(const wc_thread_tuner *t)
{
    int32_t steps = 0;
    for (int32_t k = 0; k < t->probe_step; ++k) steps += !PROBE_ORDER[k];
    return steps ? (t->block_chosen[0] + t->block_chosen[1]) / steps : 0.0;
}

static void record_probe_step(wc_thread_tuner *t, double seconds)
{
    int32_t block = t->probe_step / 4, probed = PROBE_ORDER[t->probe_step];
    if (probed) t->block_probed[block] += seconds;
    else t->block_chosen[block] += seconds;
    ++t->probe_step;
    double chosen = chosen_step_time(t);
    if (probed && chosen > 0.0 && seconds > ABANDON * chosen) {
        /* clearly lost: no more of its steps (under load one of them can
         * take tens of the chosen count's) */
        back_off(t, seconds / chosen - 1.0);
        finish_probe(t);
        return;
    }
    if (t->probe_step == WC_TUNER_PROBE_STEPS) {
        end_probe(t);
        return;
    }
    t->current = PROBE_ORDER[t->probe_step] ? t->probed : t->chosen;
}

int32_t wci_thread_tuner_first_stage(wc_thread_tuner *t, double seconds)
{
    if (!t->adapt || !t->probed || t->probed > t->chosen || t->warmup > 0) return t->current;
    if (!PROBE_ORDER[t->probe_step]) {
        t->stage_chosen += seconds;
        ++t->stage_chosen_steps;
        return t->current;
    }
    double chosen = t->stage_chosen_steps ? t->stage_chosen / t->stage_chosen_steps : 0.0;
    if (chosen >= EARLY_MIN_SECONDS && seconds > EARLY_ABANDON * chosen) {
        /* the probed count's extra time so far, in chosen-count steps */
        double step = chosen_step_time(t);
        back_off(t, step > 0.0 ? (seconds - chosen) / step : 0.0);
        finish_probe(t);
        t->skip_record = 1;
    }
    return t->current;
}

void wci_thread_tuner_record(wc_thread_tuner *t, double seconds)
{
    WC_ASSERT(t->current >= 1 && t->current <= t->most);
    if (!t->adapt) return;
    if (t->skip_record) {
        t->skip_record = 0;
        return;
    }
    if (t->warmup > 0) {
        --t->warmup;
        return;
    }
    if (t->probed) {
        record_probe_step(t, seconds);
        return;
    }
    t->recent[t->recent_next] = seconds;
    t->recent_next = (t->recent_next + 1) % WC_TUNER_SAMPLES;
    if (t->recent_count < WC_TUNER_SAMPLES) ++t->recent_count;
    if (t->recent_count < WC_TUNER_SAMPLES) return;
    double now = median3(t->recent);
    if (t->reference <= 0.0) t->reference = now;
    if (now > SLOWDOWN * t->reference) {
        if (t->chosen > 1) {
            t->until_probe = 0;
            t->direction = -1;
        }
        t->reference = now;
    }
    if (--t->until_probe <= 0) start_probe(t);
}
