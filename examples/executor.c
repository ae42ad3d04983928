/* executor.c - the tool's thread pool behind the library's tt_executor
   (-j N). See tool.h for the interface.

   The pool starts its N - 1 threads the first time work arrives and keeps
   them for every later run; the thread that calls run works too, so -j N
   runs N tasks at once. Tasks are handed out one index at a time under the
   pool's lock: the library's tasks are coarse (a tile, a range of edges),
   so the lock is taken a few thousand times per run at most. The library
   splits its work the same way whatever the executor does, so the outputs
   are the same at every -j.

   Some stages hand out thousands of small batches one after another (hpm
   fits and relaxes each cluster in batches of a fraction of a
   millisecond), and a thread asleep on a condition variable takes tens of
   microseconds to wake: the caller would often finish a batch alone before
   the worker woke, then wait for the worker's last task. So a thread about
   to sleep (a worker between batches, the caller waiting for the last
   task) first watches the pool's counters for TOOL_SPIN_NS, without the
   lock. On the horse, hpm at -j 2 then takes 0.70 of its -j 1 wall time
   instead of 0.86. */

/* pthreads, sysconf and sched_getaffinity are POSIX / GNU, not C99. */
#if !defined(_GNU_SOURCE)
#define _GNU_SOURCE
#endif

#include <pthread.h>
#include <sched.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "tool.h"

typedef struct tool_pool {
    pthread_mutex_t lock;
    pthread_cond_t work_ready;      /* a new batch, or stopping */
    pthread_cond_t work_done;       /* the last task of the batch returned */
    pthread_t *threads;
    int nthreads;                   /* started (may be fewer than asked when creation fails) */
    int started;                    /* start_threads ran (whether or not it got any) */
    int stopping;
    /* The batch in progress: indices [next, count) are still to hand out,
       `finished` have returned. `generation` counts batches, so a waking
       worker knows whether there is a new one. */
    tt_task_fn task;
    void *task_context;
    int count, next, finished, active;
    unsigned long generation, completed; /* batches handed out; the last one whose tasks all returned */
} tool_pool;

/* -j: 0 until set (tool_jobs then gives the default). */
static int g_jobs;
static tool_pool g_pool = {PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, PTHREAD_COND_INITIALIZER,
                           NULL, 0, 0, 0, NULL, NULL, 0, 0, 0, 0, 0, 0};

void tool_set_jobs(int jobs)
{
    g_jobs = jobs;
}

int tool_default_jobs(void)
{
#if defined(__linux__) && defined(CPU_COUNT)
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
#endif
    {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        if (n < 1) return 1;
        return n > TOOL_MAX_JOBS ? TOOL_MAX_JOBS : (int)n;
    }
}

int tool_jobs(void)
{
    if (g_jobs == 0) g_jobs = tool_default_jobs();
    return g_jobs;
}

/* How long a thread about to sleep first watches for the change it waits
   for: several wake-ups' worth, short beside any batch worth splitting. */
#define TOOL_SPIN_NS 200000L

/* The counters the waiting threads watch are written under the lock and,
   while spinning, read without it: atomically where the compiler has the
   builtins (gcc, clang); elsewhere the threads sleep at once. */
#if defined(__GNUC__)
#define TOOL_CAN_SPIN 1
#define TOOL_LOAD(x) __atomic_load_n(&(x), __ATOMIC_ACQUIRE)
#define TOOL_STORE(x, v) __atomic_store_n(&(x), (v), __ATOMIC_RELEASE)
#else
#define TOOL_CAN_SPIN 0
#define TOOL_STORE(x, v) ((x) = (v))
#endif

/* Called with the lock held, returns with it held: watch, without the
   lock, for up to TOOL_SPIN_NS until *counter differs from `from` (or the
   pool is stopping), so that the condition wait after it usually finds the
   change made and does not sleep. */
static void spin_until_changed(tool_pool *pool, const unsigned long *counter, unsigned long from)
{
#if TOOL_CAN_SPIN
    struct timespec start, now;
    int i;
    pthread_mutex_unlock(&pool->lock);
    clock_gettime(CLOCK_MONOTONIC, &start);
    for (i = 1;; i++) {
        if (TOOL_LOAD(*counter) != from || TOOL_LOAD(pool->stopping)) break;
        if (i % 64 == 0) {
            clock_gettime(CLOCK_MONOTONIC, &now);
            if ((long)(now.tv_sec - start.tv_sec) * 1000000000L + (now.tv_nsec - start.tv_nsec) > TOOL_SPIN_NS) break;
        }
    }
    pthread_mutex_lock(&pool->lock);
#else
    (void)pool;
    (void)counter;
    (void)from;
#endif
}

/* Hand out indices of the current batch until none are left; called with
   the lock held, returns with it held. */
static void work_on_batch(tool_pool *pool)
{
    while (pool->next < pool->count) {
        int index = pool->next++;
        tt_task_fn task = pool->task;
        void *context = pool->task_context;
        pthread_mutex_unlock(&pool->lock);
        task(context, index);
        pthread_mutex_lock(&pool->lock);
        if (++pool->finished == pool->count) {
            TOOL_STORE(pool->completed, pool->generation);
            pthread_cond_broadcast(&pool->work_done);
        }
    }
}

static void *worker_main(void *argument)
{
    tool_pool *pool = (tool_pool *)argument;
    unsigned long seen = 0;
    pthread_mutex_lock(&pool->lock);
    for (;;) {
        if (!pool->stopping && pool->generation == seen) spin_until_changed(pool, &pool->generation, seen);
        while (!pool->stopping && pool->generation == seen) pthread_cond_wait(&pool->work_ready, &pool->lock);
        if (pool->stopping) break;
        seen = pool->generation;
        work_on_batch(pool);
    }
    pthread_mutex_unlock(&pool->lock);
    return NULL;
}

/* At exit: wake the workers, let them return, and join them. */
static void stop_threads(void)
{
    tool_pool *pool = &g_pool;
    int i;
    pthread_mutex_lock(&pool->lock);
    TOOL_STORE(pool->stopping, 1);
    pthread_cond_broadcast(&pool->work_ready);
    pthread_mutex_unlock(&pool->lock);
    for (i = 0; i < pool->nthreads; i++) pthread_join(pool->threads[i], NULL);
    free(pool->threads);
    pool->threads = NULL;
    pool->nthreads = 0;
}

/* Start the pool's threads (-j minus the calling thread); called once, with
   the lock held. When the system refuses a thread the pool works with the
   ones it got (none: the caller runs every task). */
static void start_threads(tool_pool *pool)
{
    int wanted = tool_jobs() - 1, i;
    pool->started = 1;
    if (wanted < 1) return;
    pool->threads = (pthread_t *)malloc((size_t)wanted * sizeof *pool->threads);
    if (!pool->threads) return;
    for (i = 0; i < wanted; i++) {
        if (pthread_create(&pool->threads[i], NULL, worker_main, pool) != 0) break;
        pool->nthreads++;
    }
    if (pool->nthreads > 0) atexit(stop_threads);
}

static void pool_run(int count, tt_task_fn task, void *task_context, void *user_data)
{
    tool_pool *pool = (tool_pool *)user_data;
    int i;
    if (count <= 0) return;
    pthread_mutex_lock(&pool->lock);
    if (!pool->started) start_threads(pool);
    if (pool->active || pool->nthreads == 0) {
        /* A task that runs work of its own (or a second thread calling in)
           while a batch is in progress: that work runs here, serially. */
        pthread_mutex_unlock(&pool->lock);
        for (i = 0; i < count; i++) task(task_context, i);
        return;
    }
    pool->task = task;
    pool->task_context = task_context;
    pool->count = count;
    pool->next = 0;
    pool->finished = 0;
    pool->active = 1;
    TOOL_STORE(pool->generation, pool->generation + 1);
    pthread_cond_broadcast(&pool->work_ready);
    work_on_batch(pool);
    if (pool->finished < pool->count) spin_until_changed(pool, &pool->completed, pool->generation - 1);
    while (pool->finished < pool->count) pthread_cond_wait(&pool->work_done, &pool->lock);
    pool->active = 0;
    pthread_mutex_unlock(&pool->lock);
}

const tt_executor *tool_executor(void)
{
    static const tt_executor executor = {pool_run, &g_pool};
    if (tool_jobs() <= 1) return NULL;
    return &executor;
}

void tool_run_tasks(const tt_executor *executor, int count, tt_task_fn task, void *context)
{
    int i;
    if (executor && executor->run && count > 1) {
        executor->run(count, task, context, executor->user_data);
        return;
    }
    for (i = 0; i < count; i++) task(context, i);
}

typedef struct range_job {
    void (*body)(void *context, int begin, int end);
    void *context;
    int n, grain;
} range_job;

static void range_task(void *context, int index)
{
    const range_job *job = (const range_job *)context;
    int begin = index * job->grain, end = job->n - begin > job->grain ? begin + job->grain : job->n;
    job->body(job->context, begin, end);
}

void tool_parallel_ranges(const tt_executor *executor, int n, int grain, void (*body)(void *context, int begin, int end),
                          void *context)
{
    range_job job;
    if (n <= 0) return;
    job.body = body;
    job.context = context;
    job.n = n;
    job.grain = grain < 1 ? 1 : grain;
    tool_run_tasks(executor, n / job.grain + (n % job.grain != 0), range_task, &job);
}
