/* Preconditions and invariants of the library's internal functions,
 * checked in Debug and sanitizer builds and compiled out in Release (where
 * NDEBUG is defined). They state what a caller inside the library must
 * guarantee, where a comment alone would only ask for it; a failed one is a
 * bug in the library, never a user's bad input (that gets a status and a
 * message). */
#ifndef WC_INVARIANT_H
#define WC_INVARIANT_H

#ifndef NDEBUG
#include <stdio.h>
#include <stdlib.h>

/// Aborts with the condition, file and line when `cond` is false.
#define WC_ASSERT(cond)                                                           \
    do {                                                                          \
        if (!(cond)) {                                                            \
            fprintf(stderr, "%s:%d: libwetcloth invariant failed: %s\n", __FILE__, \
                    __LINE__, #cond);                                             \
            abort();                                                              \
        }                                                                         \
    } while (0)
#else
#define WC_ASSERT(cond) ((void)0)
#endif

#endif
