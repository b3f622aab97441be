// Thread counts a run can use (see thread_count.hpp).
#include "capsflow/core/driver/thread_count.hpp"

#include <pthread.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <fmt/core.h>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

namespace capsflow {

namespace {

// Starts n − 1 threads (the calling thread is the team's first) with the default attributes, as
// libgomp does without OMP_STACKSIZE, keeps them all alive at once, then ends them. Returns how
// many of the n could run, and the error of the first that could not start.
std::pair<int, int> start_threads(int n) {
  struct Gate {
    std::mutex m;
    std::condition_variable cv;
    bool open = false;
  } gate;
  auto wait = [](void* p) -> void* {
    auto* g = static_cast<Gate*>(p);
    std::unique_lock<std::mutex> lock(g->m);
    g->cv.wait(lock, [g] { return g->open; });
    return nullptr;
  };
  std::vector<pthread_t> started;
  int error = 0;
  for (int i = 1; i < n; ++i) {
    pthread_t t;
    error = ::pthread_create(&t, nullptr, +wait, &gate);
    if (error != 0) break;
    started.push_back(t);
  }
  {
    std::lock_guard<std::mutex> lock(gate.m);
    gate.open = true;
  }
  gate.cv.notify_all();
  for (pthread_t t : started) ::pthread_join(t, nullptr);
  return {static_cast<int>(started.size()) + 1, error};
}

}  // namespace

std::string thread_count_problem(int threads) {
  if (threads <= 1) return "";
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int most = kThreadsPerHardwareThread * hardware;
  if (threads > most)
    return fmt::format("more than {} × the {} hardware thread{} of this machine (give at most {})", kThreadsPerHardwareThread,
                       hardware, hardware == 1 ? "" : "s", most);
  const auto [could, error] = start_threads(threads);
  if (could < threads)
    return fmt::format("only {} of {} threads could be started here ({}: a memory or stack-size limit?)", could, threads,
                       std::strerror(error));
  return "";
}

void check_thread_count(int threads, const std::string& what) {
  if (const std::string problem = thread_count_problem(threads); !problem.empty())
    throw std::invalid_argument(what + ": " + problem);
}

}  // namespace capsflow
