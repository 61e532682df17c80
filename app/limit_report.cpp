// The voice-limit lines: rate-limited, with the numbers that explain the drop and the cures.
#include "limit_report.h"

#include <cstdio>

namespace hamiltone::app {

std::string LimitReport::update(const Player::Status& status, double seconds) {
  char line[512];
  if (status.liveTails > 0 && !tailsSaid_) {
    tailsSaid_ = true;
    std::snprintf(line, sizeof line,
                  "live tails on: the audio callback took over %g%% of its period, so decaying "
                  "strings now go linear sooner (pitch moved by under a cent) before any voice "
                  "is dropped",
                  100.0 * Player::kTailShare * context_.budget);
    return line;
  }
  if (status.limitDrops > reportedDrops_) {
    // Once every kInterval, whether or not the limit came back in between: a load that hovers at
    // the budget takes it down and back every second or so.
    if (said_ && seconds - lastLine_ < kInterval) return "";
    const long drops = status.limitDrops - reportedDrops_;
    reportedDrops_ = status.limitDrops;
    lastLine_ = seconds;
    said_ = true;
    // Drops undone by the time they are said: "lowered and back to 16".
    lowered_ = status.limit < context_.polyphony;
    const double periodMs = 1e3 * context_.frames / context_.sampleRate;
    char times[32] = "";
    if (drops > 1) std::snprintf(times, sizeof times, " (%ld times)", drops);
    char threads[96] = "";
    if (context_.threads < context_.cores)
      std::snprintf(threads, sizeof threads, ", more --threads (%d now, %d cores)",
                    context_.threads, context_.cores);
    char now[48];
    if (lowered_)
      std::snprintf(now, sizeof now, "to %d of %d", status.limit, context_.polyphony);
    else
      std::snprintf(now, sizeof now, "and back to %d", context_.polyphony);
    std::snprintf(line, sizeof line,
                  "voice limit lowered%s %s: the audio callback took %.0f%% of its "
                  "%.1f ms period (%d frames at %.0f Hz), over the %g%% budget; to keep more "
                  "voices use a larger buffer (%s%d)%s, or fewer --voices",
                  times, now, 100.0 * status.dropLoad, periodMs, context_.frames,
                  context_.sampleRate, 100.0 * context_.budget,
                  context_.jack ? "the JACK server's period, jackd -p " : "--buffer ",
                  2 * context_.frames, threads);
    return line;
  }
  if (lowered_ && status.limit >= context_.polyphony) {
    lowered_ = false;
    std::snprintf(line, sizeof line, "voice limit back to %d", context_.polyphony);
    return line;
  }
  return "";
}

}  // namespace hamiltone::app
