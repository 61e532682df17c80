// What a JACK server's log says about a run: its xrun reports.
#pragma once

#include <sstream>
#include <string>

namespace hamiltone::testing {

// The xrun reports in the server's log: its own timer firing late ("JackTimedDriver::Process
// XRun"), or a client that had not finished its cycle ("JackEngine::XRun: client = …").
inline long xrunReports(const std::string& jackdLog) {
  long reports = 0;
  std::istringstream lines(jackdLog);
  for (std::string line; std::getline(lines, line);)
    if (line.find("XRun") != std::string::npos) ++reports;
  return reports;
}

}  // namespace hamiltone::testing
