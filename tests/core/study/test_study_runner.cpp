// study_runner in process: while a variant runs, its own info lines are hidden and a heartbeat
// line reports the time it has reached (the executable's tests cover the rest: tests/app/test_study.cpp).
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>

#include "capsflow/core/study/study_runner.hpp"

using namespace capsflow;
namespace fs = std::filesystem;

TEST(StudyRunner, HidesTheRunsInfoLinesAndBeatsWhileAVariantRuns) {
  const fs::path dir = fs::temp_directory_path() / ("capsflow-study-runner-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  std::ostringstream captured;
  const auto saved = spdlog::default_logger();
  spdlog::set_default_logger(
      std::make_shared<spdlog::logger>("", std::make_shared<spdlog::sinks::ostream_sink_mt>(captured)));
  study::StudyOptions o;
  o.overrides = {"wall.model=membrane", "wall.law=nh", "flow.ca_s=0.2", "time.t_end=0.3", "output.every=0.05"};
  o.levels = {3};
  o.dir = dir;
  o.threads = 1;  // this process has no passive OpenMP wait policy (app/main.cpp): spinning threads crawl on a shared machine
  o.heartbeat_seconds = 0.05;  // the run takes ~1 s: several beats
  const int code = study::run_study(o);
  spdlog::set_default_logger(saved);
  fs::remove_all(dir);
  const std::string out = captured.str();
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("L3: t = "), std::string::npos) << out;         // a heartbeat with the time reached
  EXPECT_NE(out.find(" of 0.3 after "), std::string::npos) << out;
  EXPECT_EQ(out.find("boundary integral:"), std::string::npos) << out;  // the run's own start-up lines are hidden
  EXPECT_NE(out.find("L3: t_end at t = 0.3"), std::string::npos) << out;  // and the study's own lines are not
  EXPECT_EQ(spdlog::default_logger()->level(), spdlog::level::info);    // the level is restored
}
