/* Error reporting: every failing call fills a message that names what was
 * wrong (which field, which index, what was expected, what was found). */
#ifndef WC_STATUS_H
#define WC_STATUS_H

#include "wetcloth.h"

#if defined(__GNUC__)
#define WC_PRINTF(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define WC_PRINTF(fmt, args)
#endif

/// Writes a formatted message into msg (which may be NULL) and returns status.
wc_status wci_fail(wc_message *msg, wc_status status, const char *format, ...) WC_PRINTF(3, 4);

/// Index of the first non-finite value of values[0 .. count), or -1.
long wci_first_non_finite(const double *values, long count);

#endif
