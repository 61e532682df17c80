// The recipe's build (preset text or file, overrides, Synth::prepare) and the loader's thread:
// it polls the recipe every kPollMs, builds it once it has held still for a poll, and frees what
// the audio thread gives back.
#include "synth_loader.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "bundled_presets.h"
#include "presets/preset_loader.h"
#include "util/format_number.h"

namespace hamiltone::plugin {

namespace {

// NAME=VALUE pieces, one a line or ;-separated; blank pieces and # comments are skipped.
std::vector<PresetOverride> overridesOf(const std::string& text) {
  std::vector<PresetOverride> overrides;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = std::min(text.find_first_of(";\n", start), text.size());
    const std::string piece = text.substr(start, end - start);
    start = end + 1;
    const size_t first = piece.find_first_not_of(" \t\r");
    if (first == std::string::npos || piece[first] == '#') continue;
    std::optional<PresetOverride> o = parseOverride(piece);
    // A host's log takes one line: a megabyte of junk is named by its start.
    if (!o)
      throw std::invalid_argument("overrides: " + shownInMessage(piece, true) +
                                  ": expected NAME=VALUE");
    overrides.push_back(std::move(*o));
  }
  return overrides;
}

}  // namespace

std::unique_ptr<BuiltSynth> buildSynth(const SynthRecipe& recipe) {
  // The voices are checked by Synth::prepare at the host's rate, which is the check that counts.
  const PresetOptions options{.checkVoices = false,
                              .overrides = overridesOf(recipe.overrides),
                              .overrideLabel = "overrides: "};
  std::vector<Instrument> instruments;
  if (!recipe.file.empty()) {
    instruments.push_back(loadPreset(recipe.file, options));
  } else {
    const auto presets = bundledPresets();
    if (recipe.bundled < 0 || recipe.bundled >= static_cast<int>(presets.size()))
      throw std::invalid_argument("preset " + std::to_string(recipe.bundled) + ": there are " +
                                  std::to_string(presets.size()) + " bundled presets");
    const BundledPreset& preset = presets[recipe.bundled];
    instruments.push_back(parsePreset(preset.text, preset.file, options));
  }
  auto built = std::make_unique<BuiltSynth>();
  built->recipe = recipe;
  // The host's audio thread alone renders (threads = 1): hosts spread their plugins over the
  // cores, and a pool of workers per instance would compete with them.
  built->synth.prepare(
      std::move(instruments),
      {.sampleRate = recipe.sampleRate, .maxBlock = kMaxBlock, .notes = {}, .threads = 1});
  return built;
}

SynthLoader::~SynthLoader() { stop(); }

// Sequentially consistent, as settle()'s store and load: one of two racing stores is "loading".
void SynthLoader::setBundled(int index) noexcept {
  if (bundled_.exchange(index) != index) status_.store(LoadStatus::loading);
}

void SynthLoader::setFile(std::string file) { change(file_, std::move(file)); }

void SynthLoader::setOverrides(std::string overrides) { change(overrides_, std::move(overrides)); }

void SynthLoader::change(std::string& field, std::string value) {
  {
    const std::lock_guard lock(mutex_);
    if (value == field) return;
    field = std::move(value);
    status_.store(LoadStatus::loading, std::memory_order_release);
  }
  wake_.notify_one();
}

bool SynthLoader::giveBack(BuiltSynth* done) noexcept {
  BuiltSynth* empty = nullptr;
  return givenBack_.compare_exchange_strong(empty, done, std::memory_order_acq_rel);
}

std::string SynthLoader::file() const {
  const std::lock_guard lock(mutex_);
  return file_;
}

std::string SynthLoader::overrides() const {
  const std::lock_guard lock(mutex_);
  return overrides_;
}

std::string SynthLoader::error() const {
  const std::lock_guard lock(mutex_);
  return error_;
}

SynthRecipe SynthLoader::wanted() const {
  return {.bundled = bundled_.load(std::memory_order_relaxed),
          .file = file_,
          .overrides = overrides_,
          .sampleRate = sampleRate_};
}

void SynthLoader::build(const SynthRecipe& recipe) {
  status_.store(LoadStatus::loading, std::memory_order_release);
  try {
    publish(buildSynth(recipe));
    {
      const std::lock_guard lock(mutex_);
      error_.clear();
    }
    outcome_.store(LoadStatus::ready, std::memory_order_release);
    settle(recipe, LoadStatus::ready);
  } catch (const std::exception& e) {
    // Hosts keep a plugin's stderr in their log. The synthesizer playing before plays on — but
    // when none plays yet, for a preset file this machine cannot read (a session moved here
    // without it), or when the Preset knob chose another bundled preset the overrides do not
    // fit: then the bundled preset the knob names stands in (hosts without a UI for the plugin's
    // strings leave the knob the only way out).
    std::string why = e.what();
    const bool otherBundled =
        recipe.file.empty() && playing_ && playing_->bundled != recipe.bundled;
    if (!playing_ || otherBundled || fileUnreadable(recipe))
      why += standIn(recipe, /*anyBundled=*/!playing_);
    {
      const std::lock_guard lock(mutex_);
      error_ = why;
    }
    outcome_.store(LoadStatus::failed, std::memory_order_release);
    settle(recipe, LoadStatus::failed);
    std::fprintf(stderr, "hamiltone plugin: %s\n", why.c_str());
  }
}

// One the audio thread has not taken yet is superseded: it can no longer take it.
void SynthLoader::publish(std::unique_ptr<BuiltSynth> built) {
  playing_ = built->recipe;
  delete built_.exchange(built.release(), std::memory_order_acq_rel);
}

// The outcome becomes the status only while `recipe` is still the one asked for: one asked for
// since (a knob moved during the build) is loading until it is built in turn. The knob's index
// is read again after the store: setBundled() stores "loading" after its index, so one of the two
// stores that race is "loading".
void SynthLoader::settle(const SynthRecipe& recipe, LoadStatus outcome) {
  const std::lock_guard lock(mutex_);
  status_.store(wanted() == recipe ? outcome : LoadStatus::loading);
  if (bundled_.load() != recipe.bundled) status_.store(LoadStatus::loading);
}

// The same instrument: the same recipe, or the same preset file (the index is not read then).
bool SynthLoader::playsAlready(const SynthRecipe& playing, const SynthRecipe& recipe) {
  if (playing == recipe) return true;
  return !playing.file.empty() && playing.file == recipe.file &&
         playing.overrides == recipe.overrides && playing.sampleRate == recipe.sampleRate;
}

bool SynthLoader::fileUnreadable(const SynthRecipe& recipe) {
  if (recipe.file.empty()) return false;
  try {
    loadPreset(recipe.file, {.checkVoices = false});
    return false;
  } catch (const std::exception&) {
    return true;
  }
}

// The bundled preset the recipe's index names (the first, if it names none) with the recipe's
// overrides, then without them, then — `anyBundled`, when nothing plays — the other bundled
// presets in their order: the first that builds at the rate is left for take(). Says which.
std::string SynthLoader::standIn(const SynthRecipe& refused, bool anyBundled) {
  const auto presets = bundledPresets();
  const int count = static_cast<int>(presets.size());
  const int first = refused.bundled >= 0 && refused.bundled < count ? refused.bundled : 0;
  std::vector<SynthRecipe> candidates;
  if (!refused.overrides.empty())
    candidates.push_back(
        {.bundled = first, .overrides = refused.overrides, .sampleRate = refused.sampleRate});
  for (int i = 0; i < (anyBundled ? count : 1); ++i)
    candidates.push_back({.bundled = (first + i) % count, .sampleRate = refused.sampleRate});
  for (const SynthRecipe& candidate : candidates) {
    if (candidate == refused) continue;  // refused already
    if (!(playing_ == candidate)) {      // standing in already: not built again
      try {
        publish(buildSynth(candidate));
      } catch (const std::exception&) {
        continue;  // the next (at this rate some presets cannot be built)
      }
    }
    return std::string("; playing the bundled \"") + presets[candidate.bundled].name + "\"" +
           (candidate.overrides.empty() ? "" : " with the overrides") +
           " until a preset that builds is chosen";
  }
  if (playing_) return "; the instrument before plays on";
  if (!(refused.sampleRate > 0.0))
    return "; the host's sample rate is no rate (8000 to 384000 Hz): silent";
  return "; no bundled preset builds at " + formatNumber(refused.sampleRate) +
         " Hz either: silent until one that does is chosen";
}

void SynthLoader::freeGivenBack() {
  delete givenBack_.exchange(nullptr, std::memory_order_acq_rel);
}

void SynthLoader::start(double sampleRate) {
  stop();
  SynthRecipe recipe;
  {
    const std::lock_guard lock(mutex_);
    // NaN would make every recipe differ from itself, and the thread build it again each poll.
    sampleRate_ = std::isfinite(sampleRate) ? sampleRate : 0.0;
    stopping_ = false;
    recipe = attempted_ = wanted();
    playing_.reset();  // deactivate freed what played
  }
  build(recipe);
  thread_ = std::thread(&SynthLoader::run, this);
}

void SynthLoader::stop() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  delete built_.exchange(nullptr, std::memory_order_acq_rel);
  freeGivenBack();
}

// A recipe is built once it has held for one poll: a state restored key by key, or a preset knob
// swept across several, is built once, at its end.
void SynthLoader::run() {
  std::unique_lock lock(mutex_);
  SynthRecipe previous = attempted_;
  while (!stopping_) {
    wake_.wait_for(lock, std::chrono::milliseconds(kPollMs));
    if (stopping_) break;
    freeGivenBack();
    const SynthRecipe recipe = wanted();
    if (recipe == attempted_) {  // unchanged, or changed and changed back
      previous = recipe;
      status_.store(outcome_.load());
      if (bundled_.load() != recipe.bundled) status_.store(LoadStatus::loading);  // as settle()
      continue;
    }
    // What plays already (a stand-in whose file was cleared, overrides refused and taken back,
    // the knob moved under a preset file, which wins over it): nothing to build — a swap would
    // cut every note for the same instrument.
    if (playing_ && playsAlready(*playing_, recipe)) {
      attempted_ = previous = recipe;
      error_.clear();
      outcome_.store(LoadStatus::ready);
      status_.store(LoadStatus::ready);
      if (bundled_.load() != recipe.bundled) status_.store(LoadStatus::loading);  // as settle()
      continue;
    }
    status_.store(LoadStatus::loading, std::memory_order_release);
    if (!(recipe == previous)) {
      previous = recipe;
      continue;
    }
    attempted_ = recipe;
    lock.unlock();
    build(recipe);
    lock.lock();
  }
}

}  // namespace hamiltone::plugin
