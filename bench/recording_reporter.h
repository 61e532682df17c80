// A Google Benchmark reporter that prints the console table and keeps each run's time and
// counters, so that the summaries the benchmark programs print come from the very same runs.
#pragma once

#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

namespace hamiltone {

// The console table, plus each benchmark's real time per iteration and its counters, so that the
// summary after the run comes from the very runs the table shows.
class RecordingReporter : public benchmark::ConsoleReporter {
 public:
  struct Record {
    double seconds;  // real time per iteration
    benchmark::UserCounters counters;
  };

  // Tabular without colour: the output mostly ends up in logs, where escape codes are noise.
  RecordingReporter() : ConsoleReporter(OO_Tabular) {}

  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    // With --benchmark_repetitions the median arrives after the single runs and replaces them.
    for (const Run& run : runs) {
      const bool median = run.run_type == Run::RT_Aggregate && run.aggregate_name == "median";
      if (run.error_occurred || !(run.run_type == Run::RT_Iteration || median)) continue;
      records_[run.run_name.function_name] = {
          run.GetAdjustedRealTime() / benchmark::GetTimeUnitMultiplier(run.time_unit),
          run.counters};
    }
  }

  const Record* find(const std::string& name) const {
    const auto it = records_.find(name);
    return it == records_.end() ? nullptr : &it->second;
  }

 private:
  std::map<std::string, Record> records_;
};

}  // namespace hamiltone
