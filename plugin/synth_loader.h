// Builds the plugin's synthesizer away from the audio thread and hands it over without a lock:
// the recipe (a bundled preset or a preset file, overrides, the host's rate) is watched by a
// thread of the loader's own, which builds a new Synth whenever the recipe changes and leaves it
// in a slot the audio thread takes it from; the audio thread hands the old one back through
// another slot, and the loader's thread frees it (as chowdsp's UIToAudioPipeline does).
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "plugin_parameters.h"
#include "synth/synth.h"

namespace hamiltone::plugin {

// What a synthesizer is built from.
struct SynthRecipe {
  int bundled = 0;             // bundledPresets()[bundled], when `file` is empty
  std::string file = {};       // a preset file of the player's, which wins over `bundled`
  std::string overrides = {};  // NAME=VALUE lines (or ;-separated), as hamiltone-render's --set
  double sampleRate = 48000.0;
  bool operator==(const SynthRecipe&) const = default;
};

struct BuiltSynth {
  SynthRecipe recipe;
  Synth synth;
};

// The synthesizer for `recipe`, for blocks of any size (Synth splits them at kMaxBlock). Throws
// std::exception saying what is wrong: the file, line and key of a bad preset or override, or the
// note a voice refuses at this rate. Parses, builds and allocates: never on the audio thread.
std::unique_ptr<BuiltSynth> buildSynth(const SynthRecipe& recipe);
inline constexpr int kMaxBlock = 256;

class SynthLoader {
 public:
  SynthLoader() = default;
  ~SynthLoader();  // stops the thread; frees what the slots hold
  SynthLoader(const SynthLoader&) = delete;
  SynthLoader& operator=(const SynthLoader&) = delete;

  // Any thread, real-time safe: which bundled preset to play (an atomic the thread looks at every
  // kPollMs).
  void setBundled(int index) noexcept;
  // Not the audio thread: the preset file and the overrides (the plugin's state); wake the thread.
  void setFile(std::string file);
  void setOverrides(std::string overrides);
  // Not the audio thread: the strings as set (what the session saves).
  std::string file() const;
  std::string overrides() const;

  // Not the audio thread, with no audio thread running (the plugin's activate): builds the recipe
  // at `sampleRate` here and now, leaves it for take(), then starts the thread that follows the
  // recipe's changes.
  void start(double sampleRate);
  // The same moment (deactivate): stops the thread and frees the slots' synthesizers.
  void stop();

  // The audio thread. take(): the newest built synthesizer, now the caller's, or nullptr.
  // giveBack(): returns one the caller is done with, to be freed by the loader's thread; false
  // (and the caller keeps it) while the previous one has not been freed yet.
  BuiltSynth* take() noexcept { return built_.exchange(nullptr, std::memory_order_acq_rel); }
  bool giveBack(BuiltSynth* done) noexcept;

  // Any thread: whether the recipe asked for last is waiting or being built (loading from the
  // moment a setter changes it), built, or refused; and (not the audio thread) why it was refused.
  // "ready" comes after take() can return the build, and only while its recipe is still the one
  // asked for. A refusal leaves the synthesizer playing before, but for three cases, where a
  // bundled one stands in (without the file; the error names it): when none has been built since
  // start() — the recipe's index with its overrides, then without, then the others in order, the
  // first that builds; when the recipe's preset file cannot be read or parsed, or (with no file)
  // the index changed to one the overrides do not fit — that index, with its overrides, then
  // without (if neither builds at the rate, the one before plays on). A recipe of the instrument
  // that plays (the same recipe, or the same file whatever the index) builds nothing.
  LoadStatus status() const noexcept { return status_.load(std::memory_order_acquire); }
  std::string error() const;

  static constexpr int kPollMs = 20;

 private:
  void change(std::string& field, std::string value);  // a string of the recipe, under mutex_
  SynthRecipe wanted() const;
  void build(const SynthRecipe& recipe);            // into built_, or the status failed
  void publish(std::unique_ptr<BuiltSynth> built);  // into built_, as playing_
  void settle(const SynthRecipe& recipe, LoadStatus outcome);
  static bool playsAlready(const SynthRecipe& playing, const SynthRecipe& recipe);
  static bool fileUnreadable(const SynthRecipe& recipe);  // its file, alone, cannot be loaded
  std::string standIn(const SynthRecipe& refused, bool anyBundled);  // says which
  void freeGivenBack();
  void run();

  std::atomic<int> bundled_{0};
  std::atomic<LoadStatus> status_{LoadStatus::loading};
  std::atomic<LoadStatus> outcome_{LoadStatus::loading};  // of the recipe attempted last
  std::atomic<BuiltSynth*> built_{nullptr}, givenBack_{nullptr};

  // The recipe of the synthesizer built last since start(), if any: only the loader's thread
  // touches it, and start() before that thread exists.
  std::optional<SynthRecipe> playing_;

  mutable std::mutex mutex_;  // guards what follows; never taken by the audio thread
  std::condition_variable wake_;
  std::string file_, overrides_, error_;
  double sampleRate_ = 48000.0;
  SynthRecipe attempted_;  // the recipe built last, successfully or not
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace hamiltone::plugin
