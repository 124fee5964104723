/* OpenMP settings shared by the per-step loops. Every parallel loop writes
 * each output element from exactly one iteration, so results never depend on
 * the thread count. */
#ifndef WC_PARALLEL_H
#define WC_PARALLEL_H

/// Loops with fewer iterations than this run on one thread: below it, waking
/// the thread team costs more than the loop itself.
#define WC_PARALLEL_MIN 4096

/// Threads to use for a world's thread_count setting (0 = OpenMP default).
int wc_thread_count(int requested);

#endif
