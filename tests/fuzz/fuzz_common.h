/* fuzz_common.h - what every fuzz target in tests/fuzz shares: the contract
   check, a counting allocator that can fail once (passed to the library as a
   tt_allocator parameter), and a byte reader.

   Define FUZZ_NAME ("fuzz_obj") before including; include after tiledtex.h.
   The functions are static inline so a target that needs only CHECK stays
   warning-free.

   The contract (THE API CONTRACT at the top of tiledtex.h) as checked here:
     - on failure: the result is negative, error->result equals it, the
       message is non-empty and NUL-terminated inside the buffer and holds no
       run of more than 12 digits (numbers are printed compactly), every
       `T **out` is NULL (fz_check_null), and TT_ERROR_OUT_OF_MEMORY only
       when the counting allocator really failed an allocation;
     - after the caller has freed every object (tt_*_free), the allocator's
       live count is back to zero (fz_check_all_freed). */
#ifndef TILEDTEX_FUZZ_COMMON_H
#define TILEDTEX_FUZZ_COMMON_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    tt_allocator tt;    /* what the library is given: &a.tt */
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
        CHECK(a->live > 0, "freeing %p with no live allocation", p);
        a->live--;
        free(p);
    }
}

/* Zero the counters; allocation number fail_at (1-based, 0 = none) fails. */
static inline const tt_allocator *fz_alloc_init(fz_alloc *a, long fail_at)
{
    memset(a, 0, sizeof *a);
    a->fail_at = fail_at;
    a->tt.alloc = fz_malloc;
    a->tt.free = fz_free;
    a->tt.user_data = a;
    return &a->tt;
}

/* Every object the caller got has been freed: nothing is left live. */
#define fz_check_all_freed(a)                                                                       \
    CHECK((a)->live == 0, "%ld allocations not freed (of %ld made, failing number %ld)", (a)->live, \
          (a)->count, (a)->fail_at)

/* On failure every `T **out` must be NULL. */
#define fz_check_null(what, r, out) CHECK((out) == NULL, "%s failed (%d) but its output is not NULL", what, (int)(r))

/* An error that the library filled: call it with memset(&err, 0x55, ...) done
   before the call, so a field left unwritten shows. `a` may be NULL (an
   allocator that never fails: then out of memory is never right). */
static inline void fz_check_error(const char *what, tt_result r, const tt_error *err, const fz_alloc *a)
{
    size_t len = 0, i, run = 0, longest = 0;
    while (len < sizeof err->message && err->message[len]) ++len;
    CHECK(r < 0, "%s: result %d", what, (int)r);
    CHECK(len > 0 && len < sizeof err->message, "%s: message length %lu (no NUL inside the buffer, or empty)", what,
          (unsigned long)len);
    CHECK(err->result == r, "%s: err.result %d, returned %d (%s)", what, (int)err->result, (int)r, err->message);
    for (i = 0; i < len; ++i) {
        run = (err->message[i] >= '0' && err->message[i] <= '9') ? run + 1 : 0;
        if (run > longest) longest = run;
    }
    CHECK(longest <= 12, "%s: a run of %lu digits in the message: %s", what, (unsigned long)longest, err->message);
    CHECK(r != TT_ERROR_OUT_OF_MEMORY || (a && a->failed), "%s: out of memory with no failed allocation: %s", what,
          err->message);
}

/* ---- input reader: missing bytes read as 0 ---------------------------------- */

typedef struct reader {
    const uint8_t *p;
    size_t n, at;
} reader;

static inline uint8_t rd_u8(reader *r) { return r->at < r->n ? r->p[r->at++] : 0; }
static inline size_t rd_left(const reader *r) { return r->n - r->at; }

/* A progress callback that checks the contract (fractions in [0, 1], never
   decreasing) and cancels after cancel_after calls (0 = never). */
typedef struct fz_progress {
    float last;
    int calls;
    int cancel_after;
} fz_progress;

static inline int fz_on_progress(float fraction, void *user)
{
    fz_progress *ps = (fz_progress *)user;
    CHECK(fraction >= 0.0f && fraction <= 1.0f, "progress fraction %g", (double)fraction);
    CHECK(fraction >= ps->last, "progress went back from %g to %g", (double)ps->last, (double)fraction);
    ps->last = fraction;
    ps->calls++;
    return ps->cancel_after > 0 && ps->calls >= ps->cancel_after;
}

/* ---- extreme floats --------------------------------------------------------- */

/* Values that break naive arithmetic, for the targets' extreme-float modes:
   overflow when subtracted or squared (+-FLT_MAX, +-1e38), underflow and
   denormals (1e-38, 1e-40, 1e-45), -0.0, the infinities, and NaNs with
   payloads and either sign (a NaN test that compares bit patterns, or
   passes a payload through, shows). Built from bits so no constant
   expression overflows. */
static inline float fz_extreme_float(uint8_t b)
{
    static const uint32_t bits[24] = {
        0x7f7fffffu, 0xff7fffffu, /* +-FLT_MAX */
        0x7e967699u, 0xfe967699u, /* +-1e38 */
        0x006ce3eeu, 0x806ce3eeu, /* +-1e-38 (normal, near FLT_MIN) */
        0x00011d10u, 0x80011d10u, /* +-1e-40 (denormal) */
        0x00000001u, 0x80000001u, /* +-1e-45 (the smallest denormal) */
        0x00800000u, 0x007fffffu, /* FLT_MIN, the largest denormal */
        0x00000000u, 0x80000000u, /* +0.0, -0.0 */
        0x7f800000u, 0xff800000u, /* +-infinity */
        0x7fc00000u, 0xffc00000u, /* quiet NaN, negative quiet NaN */
        0x7fc00123u, 0xffc4d2e1u, /* quiet NaNs with payloads */
        0x7f800001u, 0xffbfffffu, /* signalling NaNs (payload 1, all ones) */
        0x4b800000u, 0x4b800001u  /* 2^24 and the next float: differences collapse */
    };
    uint32_t u = bits[b % 24];
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* The same for option doubles: +-DBL_MAX, +-1e308, denormals, -0.0,
   infinities, NaNs with payloads, and the float extremes widened. */
static inline double fz_extreme_double(uint8_t b)
{
    static const uint64_t bits[10] = {
        0x7fefffffffffffffu, 0xffefffffffffffffu, /* +-DBL_MAX */
        0x0000000000000001u, 0x8000000000000001u, /* +-4.9e-324 */
        0x000fffffffffffffu, 0x8000000000000000u, /* the largest denormal, -0.0 */
        0x7ff8000000000123u, 0xfff4000000000001u, /* NaNs with payloads (quiet, signalling) */
        0x7ff0000000000000u, 0xfff0000000000000u  /* +-infinity */
    };
    double d;
    if (b % 34 < 10) {
        memcpy(&d, &bits[b % 34], sizeof d);
        return d;
    }
    return (double)fz_extreme_float((uint8_t)(b % 34 - 10));
}

#endif /* TILEDTEX_FUZZ_COMMON_H */
