/* How many of the machine's cores sat idle over a stretch of time: the
 * operating system's count of idle processor time, summed over all its
 * processors, read at both ends. The thread tuner asks it before it tries
 * more threads (thread_tuner.h): with every core busy (another program on
 * the cores the world's threads would need) such a try can only lose, and
 * one step of it can cost many. */
#ifndef WC_IDLE_CORES_H
#define WC_IDLE_CORES_H

/// A stretch of time being measured.
typedef struct wc_idle_meter {
    /// Idle processor seconds, summed over the processors, and the wall
    /// clock (seconds) at the stretch's start.
    double idle_seconds;
    double wall_seconds;
    /// 0 where the system gives no count (the meter then says "unknown").
    int known;
} wc_idle_meter;

/// Starts a stretch now.
void wci_idle_meter_start(wc_idle_meter *meter);

/// The mean number of idle cores since the stretch started (>= 0), and a
/// new stretch from now; WC_IDLE_UNKNOWN when the system gives no count;
/// WC_IDLE_TOO_SOON, the stretch going on, while it is shorter than
/// WC_IDLE_MIN_WINDOW (the counts advance in ticks of 10 ms on Linux and
/// macOS: over 0.1 s a 2-core machine's count is within 0.2 cores).
double wci_idle_meter_read(wc_idle_meter *meter);

#define WC_IDLE_UNKNOWN (-1.0)
#define WC_IDLE_TOO_SOON (-2.0)

/// Seconds a stretch must last to be read.
#define WC_IDLE_MIN_WINDOW 0.1

#endif
