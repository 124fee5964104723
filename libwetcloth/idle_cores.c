/* The idle time of every processor, summed, from the system: /proc/stat on
 * Linux, GetSystemTimes on Windows, the host's load counters on macOS.
 * None of them is C99 (sysconf, the Mach calls, the Windows API): asked for
 * here, in this file only, as clock.c does. Elsewhere the count is unknown
 * and the tuner tries more threads without asking. */
#if defined(__APPLE__)
#define _DARWIN_C_SOURCE
#elif !defined(_WIN32)
#define _POSIX_C_SOURCE 200112L
#endif
#include "idle_cores.h"

#include "clock.h"

#if defined(_WIN32)
#define WIN32_LEAN_AND_MEAN
#include <windows.h>

static int idle_processor_seconds(double *out)
{
    FILETIME idle, kernel, user;
    if (!GetSystemTimes(&idle, &kernel, &user)) return 0;
    ULARGE_INTEGER ticks; /* 100 ns each */
    ticks.LowPart = idle.dwLowDateTime, ticks.HighPart = idle.dwHighDateTime;
    *out = (double)ticks.QuadPart * 1e-7;
    return 1;
}
#elif defined(__linux__)
#include <stdio.h>
#include <unistd.h>

/* The first line of /proc/stat sums every processor's time, in clock
 * ticks: user, nice, system, idle, iowait, ... A processor waiting for
 * input or output is free to run a thread, so iowait counts as idle. */
static int idle_processor_seconds(double *out)
{
    FILE *f = fopen("/proc/stat", "r");
    if (!f) return 0;
    unsigned long long user, nice, system, idle, iowait;
    int read = fscanf(f, "cpu %llu %llu %llu %llu %llu", &user, &nice, &system, &idle, &iowait);
    fclose(f);
    long tick = sysconf(_SC_CLK_TCK);
    if (read != 5 || tick <= 0) return 0;
    *out = (double)(idle + iowait) / (double)tick;
    return 1;
}
#elif defined(__APPLE__)
#include <mach/mach.h>
#include <unistd.h>

static int idle_processor_seconds(double *out)
{
    host_cpu_load_info_data_t load;
    mach_msg_type_number_t count = HOST_CPU_LOAD_INFO_COUNT;
    mach_port_t host = mach_host_self();
    kern_return_t status = host_statistics(host, HOST_CPU_LOAD_INFO, (host_info_t)&load, &count);
    mach_port_deallocate(mach_task_self(), host);
    long tick = sysconf(_SC_CLK_TCK);
    if (status != KERN_SUCCESS || tick <= 0) return 0;
    *out = (double)load.cpu_ticks[CPU_STATE_IDLE] / (double)tick;
    return 1;
}
#else
static int idle_processor_seconds(double *out)
{
    (void)out;
    return 0;
}
#endif

void wci_idle_meter_start(wc_idle_meter *m)
{
    m->known = idle_processor_seconds(&m->idle_seconds);
    m->wall_seconds = wci_clock_seconds();
}

double wci_idle_meter_read(wc_idle_meter *m)
{
    double wall = wci_clock_seconds(), idle;
    if (!m->known) {
        wci_idle_meter_start(m); /* the count may come back */
        return WC_IDLE_UNKNOWN;
    }
    double window = wall - m->wall_seconds;
    if (window < WC_IDLE_MIN_WINDOW) return WC_IDLE_TOO_SOON;
    if (!idle_processor_seconds(&idle)) {
        m->known = 0;
        return WC_IDLE_UNKNOWN;
    }
    double cores = (idle - m->idle_seconds) / window;
    m->idle_seconds = idle, m->wall_seconds = wall;
    return cores > 0.0 ? cores : 0.0;
}
