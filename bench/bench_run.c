/* bench_run.c - run one command and report what it cost, for
   bench/bench_scale.sh:

       build/bench_run SECONDS COMMAND [ARG ...]

   prints one line on stdout, `cpu_s wall_s peak_kib status`: user + system
   CPU seconds of the command and all it waited for, wall seconds, its peak
   resident memory in KiB, and its exit status (a signal N is 128 + N; a
   command still running after SECONDS is killed and reported as status
   "timeout"). The command's own output goes where bench_run's goes. CPU
   seconds are what the figures compare, since they do not count other jobs'
   load on a shared machine; wall seconds show what parallel work gains. */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bench_clock.h"

int main(int argc, char **argv)
{
    double limit_ms, start, wall;
    struct rusage usage;
    pid_t child;
    int status = 0, timed_out = 0;
    if (argc < 3 || (limit_ms = atof(argv[1]) * 1000.0) <= 0.0) {
        fprintf(stderr, "usage: bench_run SECONDS COMMAND [ARG ...]\n");
        return 2;
    }
    start = bench_now_ms();
    child = fork();
    if (child < 0) {
        perror("bench_run: fork");
        return 2;
    }
    if (child == 0) {
        execvp(argv[2], argv + 2);
        perror("bench_run: exec");
        _exit(127);
    }
    for (;;) {
        pid_t done = wait4(child, &status, WNOHANG, &usage);
        if (done == child) break;
        if (done < 0) {
            perror("bench_run: wait4");
            return 2;
        }
        if (!timed_out && bench_now_ms() - start > limit_ms) {
            kill(child, SIGKILL);
            timed_out = 1;
        }
        {
            struct timespec pause = {0, 20 * 1000 * 1000};
            nanosleep(&pause, NULL);
        }
    }
    wall = (bench_now_ms() - start) / 1000.0;
    printf("%.3f %.3f %ld ", (double)usage.ru_utime.tv_sec + usage.ru_utime.tv_usec * 1e-6 +
                                 (double)usage.ru_stime.tv_sec + usage.ru_stime.tv_usec * 1e-6,
           wall, usage.ru_maxrss);
    if (timed_out) printf("timeout\n");
    else if (WIFSIGNALED(status)) printf("%d\n", 128 + WTERMSIG(status));
    else printf("%d\n", WEXITSTATUS(status));
    return 0;
}
