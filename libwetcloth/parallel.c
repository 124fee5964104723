#include "parallel.h"

#ifdef _OPENMP
#include <omp.h>
#endif

int wci_thread_count(int requested)
{
#ifdef _OPENMP
    return requested > 0 ? requested : omp_get_max_threads();
#else
    (void)requested;
    return 1;
#endif
}

int wci_parallel_for(int64_t n, int threads, wc_range_fn body, void *context)
{
    if (n <= 0) return 0;
#ifdef _OPENMP
    if (threads > 1) {
        int flagged = 0;
#pragma omp parallel num_threads(threads) reduction(|| : flagged)
        {
            int64_t t = omp_get_thread_num(), nt = omp_get_num_threads();
            int64_t begin = n * t / nt, end = n * (t + 1) / nt;
            if (begin < end) flagged = body(context, begin, end) != 0;
        }
        return flagged;
    }
#else
    (void)threads;
#endif
    return body(context, 0, n) != 0;
}

void wci_parallel_team(int threads, wc_team_fn body, void *context)
{
#ifdef _OPENMP
    if (threads > 1) {
#pragma omp parallel num_threads(threads)
        {
            wc_team team = {omp_get_thread_num(), omp_get_num_threads()};
            body(context, &team);
        }
        return;
    }
#else
    (void)threads;
#endif
    wc_team team = {0, 1};
    body(context, &team);
}

void wci_team_barrier(const wc_team *team)
{
#ifdef _OPENMP
    if (team->threads > 1) {
#pragma omp barrier
    }
#else
    (void)team;
#endif
}
