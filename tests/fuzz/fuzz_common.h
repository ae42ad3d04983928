/* fuzz_common.h - what every fuzz target in tests/fuzz shares: the contract
   check, a counting allocator that can fail once, and a byte reader.

   Define FUZZ_NAME ("fuzz_obj") before including; include after tiledtex.h.
   The functions are static inline so a target that needs only CHECK stays
   warning-free. */
#ifndef TILEDTEX_FUZZ_COMMON_H
#define TILEDTEX_FUZZ_COMMON_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

/* Abort, naming the broken condition, when a result breaks the documented
   contract: libFuzzer saves the input that did it. */
#define CHECK(cond, ...)                                                   \
    do {                                                                   \
        if (!(cond)) {                                                     \
            fprintf(stderr, FUZZ_NAME ": contract broken: %s: ", #cond);   \
            fprintf(stderr, __VA_ARGS__);                                  \
            fprintf(stderr, "\n");                                         \
            abort();                                                       \
        }                                                                  \
    } while (0)

/* ---- counting allocator that can fail once ---------------------------------- */

typedef struct fz_alloc {
    long count;         /* allocations asked for */
    long live;          /* allocations not yet freed */
    long fail_at;       /* 1-based allocation number that returns NULL, 0 = none */
    int failed;         /* an allocation did fail */
} fz_alloc;

static inline void *fz_malloc(size_t size, void *user)
{
    fz_alloc *a = (fz_alloc *)user;
    void *p;
    a->count++;
    if (a->fail_at && a->count == a->fail_at) {
        a->failed = 1;
        return NULL;
    }
    p = malloc(size ? size : 1);
    if (p) a->live++;
    return p;
}

static inline void fz_free(void *p, void *user)
{
    fz_alloc *a = (fz_alloc *)user;
    if (p) {
        a->live--;
        free(p);
    }
}

/* ---- input reader: missing bytes read as 0 ---------------------------------- */

typedef struct reader {
    const uint8_t *p;
    size_t n, at;
} reader;

static inline uint8_t rd_u8(reader *r) { return r->at < r->n ? r->p[r->at++] : 0; }

#endif /* TILEDTEX_FUZZ_COMMON_H */
