// The process's own resource figures from /proc/self (resident memory, threads, open file descriptors), for the
// soak test's leak checks.
#pragma once

namespace avatarbooth {

struct ProcessFigures {
    double rssMegabytes = 0.0;      // VmRSS now
    double peakRssMegabytes = 0.0;  // VmHWM: the most resident so far
    int threads = 0;
    int openFiles = 0;              // entries of /proc/self/fd
};

ProcessFigures readProcessFigures();

}  // namespace avatarbooth
