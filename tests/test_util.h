/* Minimal test harness: CHECK records a failure with its location and goes
 * on; main returns test_report(), non-zero when anything failed. */
#ifndef WC_TEST_UTIL_H
#define WC_TEST_UTIL_H

#include <stdio.h>

extern int test_failures;

#define CHECK(cond, ...)                                                        \
    do {                                                                        \
        if (!(cond)) {                                                          \
            ++test_failures;                                                    \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                       \
            fputc('\n', stderr);                                                \
        }                                                                       \
    } while (0)

/// Prints a summary and returns the process exit code.
int test_report(const char *name);

#endif
