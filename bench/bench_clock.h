/* bench_clock.h - what every bench program times with: a monotonic clock in
   milliseconds and the comparison that sorts run times for their minimum and
   median. Valid C99 (with _POSIX_C_SOURCE 199309L defined before the first
   system header, for clock_gettime) and C++. */
#ifndef BENCH_CLOCK_H
#define BENCH_CLOCK_H

#include <time.h>

static inline double bench_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* qsort comparison of doubles, ascending. */
static inline int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#endif /* BENCH_CLOCK_H */
