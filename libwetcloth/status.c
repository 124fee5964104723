#include "status.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

wc_status wci_fail(wc_message *msg, wc_status status, const char *format, ...)
{
    if (msg) {
        va_list args;
        va_start(args, format);
        vsnprintf(msg->text, sizeof msg->text, format, args);
        va_end(args);
    }
    return status;
}

long wci_first_non_finite(const double *values, long count)
{
    for (long i = 0; i < count; ++i)
        if (!isfinite(values[i])) return i;
    return -1;
}

const char *wc_status_name(wc_status status)
{
    switch (status) {
    case WC_OK: return "WC_OK";
    case WC_ERROR_INVALID_ARGUMENT: return "WC_ERROR_INVALID_ARGUMENT";
    case WC_ERROR_OUT_OF_MEMORY: return "WC_ERROR_OUT_OF_MEMORY";
    case WC_ERROR_NON_FINITE: return "WC_ERROR_NON_FINITE";
    case WC_ERROR_NOT_FOUND: return "WC_ERROR_NOT_FOUND";
    }
    return "WC_STATUS_UNKNOWN";
}
