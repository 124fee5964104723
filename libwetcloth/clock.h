/* Wall-clock time for the step's per-phase timings (wc_step_stats). */
#ifndef WC_CLOCK_H
#define WC_CLOCK_H

/// Seconds on a monotonic clock, from an arbitrary origin.
double wci_clock_seconds(void);

#endif
