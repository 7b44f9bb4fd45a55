// How the process's heap keeps the memory it frees, for a process that allocates the same large buffers again and
// again (every fit makes and drops tens of megabytes of images, masks and texture maps).
#pragma once

namespace avatarbooth {

// Freed blocks of up to 32 MB stay in the heap for the next fit instead of going back to the kernel. glibc by default
// maps blocks over 128 kB (a threshold it raises only once such a block is freed) straight from the kernel and unmaps
// them on free, so each fit touched its buffers' pages afresh: about 10,000 page faults a fit. Peak memory is the
// same; the heap just does not shrink between visitors. Does nothing on a C library other than glibc.
void keepFreedBuffersForReuse();

}  // namespace avatarbooth
