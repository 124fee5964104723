#include "alloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "wetcloth.h"

/* The hook set with wc_set_allocator; NULL means malloc and free. */
static wc_alloc_fcn *g_alloc;
static wc_free_fcn *g_free;
static void *g_user;

void wc_set_allocator(wc_alloc_fcn *alloc_fcn, wc_free_fcn *free_fcn, void *user)
{
    if (alloc_fcn && free_fcn) {
        g_alloc = alloc_fcn;
        g_free = free_fcn;
        g_user = user;
    } else {
        g_alloc = NULL;
        g_free = NULL;
        g_user = NULL;
    }
}

void *wci_alloc_array(size_t count, size_t size)
{
    /* asking for at least one byte keeps a zero-length array distinct from a
     * failure */
    if (count == 0) count = 1;
    if (!g_alloc) return calloc(count, size); /* calloc checks count * size for overflow */
    if (size != 0 && count > SIZE_MAX / size) return NULL;
    size_t bytes = count * size;
    if (bytes == 0) bytes = 1;
    void *memory = g_alloc(bytes, g_user);
    if (memory) memset(memory, 0, bytes);
    return memory;
}

void wci_free(void *memory)
{
    if (!memory) return;
    if (g_free)
        g_free(memory, g_user);
    else
        free(memory);
}
