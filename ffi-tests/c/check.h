/* Assertion helpers for the mechanica ffi-tests. Every program in ffi-tests/c and ffi-tests/cpp
 * includes this file; a failed CHECK prints the location and exits with status 1, which fails
 * the cargo test that runs the program. */
#ifndef MECH_FFI_CHECK_H
#define MECH_FFI_CHECK_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mechanica.h"

static int mech_check_count = 0;

/** Fails the program unless `cond` holds. */
#define CHECK(cond)                                                                 \
    do {                                                                            \
        ++mech_check_count;                                                         \
        if (!(cond)) {                                                              \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
            exit(1);                                                                \
        }                                                                           \
    } while (0)

/** Fails the program unless `call` returns the status `expected`; prints the detailed message. */
#define CHECK_STATUS(call, expected)                                                      \
    do {                                                                                  \
        ++mech_check_count;                                                               \
        mech_status_t mech_got_ = (call);                                                 \
        if (mech_got_ != (expected)) {                                                    \
            char mech_msg_[512];                                                          \
            mech_last_error(mech_msg_, sizeof mech_msg_);                                 \
            fprintf(stderr, "%s:%d: %s returned %d (%s; last error: %s), expected %s\n",  \
                    __FILE__, __LINE__, #call, (int)mech_got_, mech_status_str(mech_got_), \
                    mech_msg_, #expected);                                                \
            exit(1);                                                                      \
        }                                                                                 \
    } while (0)

/** Fails the program unless |a − b| ≤ tol. */
#define CHECK_NEAR(a, b, tol)                                                                 \
    do {                                                                                      \
        ++mech_check_count;                                                                   \
        double mech_a_ = (a), mech_b_ = (b);                                                  \
        if (!(fabs(mech_a_ - mech_b_) <= (tol))) {                                            \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.17g, %s = %.17g, tol %g\n",     \
                    __FILE__, __LINE__, #a, mech_a_, #b, mech_b_, (double)(tol));             \
            exit(1);                                                                          \
        }                                                                                     \
    } while (0)

/** Fills `n` bytes at `p` with the sentinel byte 0xA5, to check later that nothing was written. */
#define FILL_SENTINEL(p, n) memset((p), 0xA5, (n))

/** True when all `n` bytes at `p` still hold the sentinel byte 0xA5. */
static inline int mech_untouched(const void *p, size_t n) {
    const unsigned char *b = (const unsigned char *)p;
    for (size_t i = 0; i < n; ++i) {
        if (b[i] != 0xA5) return 0;
    }
    return 1;
}

/** Prints the summary line; call at the end of main and return its value. */
#define CHECK_DONE() (printf("%s: %d checks passed\n", __FILE__, mech_check_count), 0)

#endif
