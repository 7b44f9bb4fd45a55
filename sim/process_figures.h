// The process's own resource figures from /proc/self (resident memory, threads, open file descriptors), for the
// soak test's leak checks and the memory benchmarks.
#pragma once

#include <map>
#include <string>

namespace avatarbooth {

struct ProcessFigures {
    double rssMegabytes = 0.0;      // VmRSS now
    double peakRssMegabytes = 0.0;  // VmHWM: the most resident so far
    double anonRssMegabytes = 0.0;  // RssAnon: of VmRSS, the process's own memory (heap, stacks, mappings)
    double fileRssMegabytes = 0.0;  // RssFile: of VmRSS, pages of mapped files (the libraries, shareable)
    int threads = 0;
    int openFiles = 0;              // entries of /proc/self/fd
};

ProcessFigures readProcessFigures();

// Resident megabytes per mapping name from /proc/self/smaps, summed over the mappings of each name: a library's
// path, "[heap]" (the brk heap: glibc's main arena), "[stack]", and for anonymous mappings "[anon: arena]" (glibc's
// other arenas), "[anon: code]" (code compiled at run time) and "[anon]" (large blocks, stacks, drivers' buffers).
// Where a slow climb of VmRSS comes from. Empty when smaps cannot be read.
std::map<std::string, double> residentByMapping();

}  // namespace avatarbooth
