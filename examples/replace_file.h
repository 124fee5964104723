/* replace_file(from, to): renames `from` over `to`, replacing `to` when it
 * exists. C's rename() does that on POSIX systems but fails on Windows when
 * `to` exists; there MoveFileExA with MOVEFILE_REPLACE_EXISTING does it.
 * Returns 0 on success; on failure nonzero with errno set (EACCES on
 * Windows, whose error is GetLastError's). */
#ifndef WC_EXAMPLES_REPLACE_FILE_H
#define WC_EXAMPLES_REPLACE_FILE_H

#include <errno.h>
#include <stdio.h>

#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
/* windows.h defines these as nothing; the examples use them as names. */
#undef near
#undef far

static int replace_file(const char *from, const char *to)
{
    if (MoveFileExA(from, to, MOVEFILE_REPLACE_EXISTING)) return 0;
    errno = EACCES;
    return -1;
}
#else
static int replace_file(const char *from, const char *to)
{
    return rename(from, to);
}
#endif

#endif
