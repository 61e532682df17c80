// What the player says when its overload protection lowered the voice limit (Player::protect):
// from the main thread, which polls Player::status(), never from the audio thread; at most one
// line every kInterval seconds, even when the limit came back in between, saying how often it
// dropped since the last line, the callback's load that made it drop against the budget, the new
// limit (or that it is back already), and what would avoid it. And one line when the limit is back
// at the polyphony. Once, the first time the protection turns the strings' live tail on.
#pragma once

#include <string>

#include "player.h"

namespace hamiltone::app {

struct LimitContext {
  double budget = Player::kOverload;  // of the buffer period
  int frames = 0;                     // the buffer the stream runs with
  double sampleRate = 0.0;
  int threads = 1, cores = 1;
  int polyphony = 0;  // the limit before any drop
  bool jack = false;  // the buffer is the JACK server's period (jackd -p), not --buffer
};

class LimitReport {
 public:
  static constexpr double kInterval = 5.0;

  explicit LimitReport(const LimitContext& context) : context_(context) {}

  // The line to print now ("" for none), given the latest status at `seconds` on any clock.
  std::string update(const Player::Status& status, double seconds);

 private:
  LimitContext context_;
  long reportedDrops_ = 0;
  double lastLine_ = 0.0;
  bool lowered_ = false;    // a drop was reported and the limit is not back yet
  bool said_ = false;       // a drop was reported (at lastLine_)
  bool tailsSaid_ = false;  // the live tail's first turn on was reported
};

}  // namespace hamiltone::app
