#pragma once
// The OpenMP thread counts a run accepts (`--threads`, Python's `threads=`; docs/scene-and-output.md
// §1). libgomp cannot report a thread it fails to start: it prints "Thread creation failed" and
// calls exit(1), which ends a Python interpreter with it and leaves a run's lock file behind. So a
// count is checked before anything is locked or written: at most kThreadsPerHardwareThread × the
// machine's hardware threads (more only slows a run down: the barriers of the rotation and mass
// solves wait for every thread), and only as many as this process can start now (a memory or
// stack-size limit), found by starting and ending that many threads.
#include <string>

namespace capsflow {

inline constexpr int kThreadsPerHardwareThread = 4;

// "" when `threads` can be used (0, OpenMP's default, always can), else why not ("more than 4 × the
// 2 hardware threads of this machine (give at most 8)", "only 2 of 3 threads could be started here …").
std::string thread_count_problem(int threads);

// Throws std::invalid_argument "WHAT: <problem>" (WHAT names the option: "--threads 4096") when
// thread_count_problem(threads) is not "".
void check_thread_count(int threads, const std::string& what);

}  // namespace capsflow
