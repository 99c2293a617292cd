// The benchmark's clock and statistic, shared by its workloads' files.
#pragma once

#include <algorithm>
#include <ctime>
#include <vector>

namespace avrbench_perf {

// CPU seconds of the calling thread: what the benchmark compares, since on a
// shared, loaded machine wall time measures the neighbours (docs/PERFORMANCE.md).
inline double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// The middle value; of an even count, the mean of the two in the middle.
inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 == 1 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace avrbench_perf
