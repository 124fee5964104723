/* All heap memory of the library goes through these two calls, so that an
 * out-of-memory path can be tested in one place. They use the hook set with
 * wc_set_allocator(), else calloc and free. */
#ifndef WC_ALLOC_H
#define WC_ALLOC_H

#include <stddef.h>

/// Zeroed array of count elements of size bytes; NULL on failure or overflow.
void *wci_alloc_array(size_t count, size_t size);

/// Frees what wci_alloc_array returned. NULL is allowed (and never reaches a hook).
void wci_free(void *memory);

#endif
