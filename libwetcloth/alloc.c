#include "alloc.h"

#include <stdlib.h>

void *wc_alloc_array(size_t count, size_t size)
{
    /* calloc checks count * size for overflow; asking for at least one byte
     * keeps a zero-length array distinct from a failure. */
    if (count == 0) count = 1;
    return calloc(count, size);
}

void wc_free(void *memory)
{
    free(memory);
}
