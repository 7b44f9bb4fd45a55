#include "common/heap_reuse.h"

#if __has_include(<malloc.h>)
#include <malloc.h>
#endif

namespace avatarbooth {

void keepFreedBuffersForReuse() {
#if defined(__GLIBC__) && defined(M_MMAP_THRESHOLD) && defined(M_TRIM_THRESHOLD)
    // 32 MB is the most glibc accepts for the mapping threshold on 64-bit; the trim threshold above it lets the
    // heap's top hold a fit's worth of freed buffers.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

}  // namespace avatarbooth
