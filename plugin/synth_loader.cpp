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
    if (!o) throw std::invalid_argument("overrides: \"" + piece + "\": expected NAME=VALUE");
    overrides.push_back(std::move(*o));
  }
  return overrides;
}

}  // namespace

std::unique_ptr<BuiltSynth> buildSynth(const SynthRecipe& recipe) {
  // The voices are checked by Synth::prepare at the host's rate, which is the check that counts.
  const PresetOptions options{.checkVoices = false, .overrides = overridesOf(recipe.overrides)};
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

void SynthLoader::setBundled(int index) noexcept {
  if (bundled_.exchange(index, std::memory_order_relaxed) != index)
    status_.store(LoadStatus::loading, std::memory_order_release);
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
    std::unique_ptr<BuiltSynth> built = buildSynth(recipe);
    // One the audio thread has not taken yet is superseded: it can no longer take it.
    delete built_.exchange(built.release(), std::memory_order_acq_rel);
    {
      const std::lock_guard lock(mutex_);
      error_.clear();
    }
    outcome_.store(LoadStatus::ready, std::memory_order_release);
    status_.store(LoadStatus::ready, std::memory_order_release);
    playable_ = true;
  } catch (const std::exception& e) {
    // Hosts keep a plugin's stderr in their log. The synthesizer playing before plays on; with
    // none (a session restored on a machine without its preset file), a bundled one stands in.
    std::string why = e.what();
    if (!playable_) why += standIn(recipe);
    {
      const std::lock_guard lock(mutex_);
      error_ = why;
    }
    outcome_.store(LoadStatus::failed, std::memory_order_release);
    status_.store(LoadStatus::failed, std::memory_order_release);
    std::fprintf(stderr, "hamiltone plugin: %s\n", why.c_str());
  }
}

// The bundled preset the recipe's index names (the first, if it names none), then the others in
// their order, each without file or overrides: the first that builds is left for take().
std::string SynthLoader::standIn(const SynthRecipe& refused) {
  const auto presets = bundledPresets();
  const int count = static_cast<int>(presets.size());
  const int first = refused.bundled >= 0 && refused.bundled < count ? refused.bundled : 0;
  for (int i = 0; i < count; ++i) {
    const SynthRecipe candidate{.bundled = (first + i) % count, .sampleRate = refused.sampleRate};
    if (candidate == refused) continue;  // refused already
    try {
      delete built_.exchange(buildSynth(candidate).release(), std::memory_order_acq_rel);
      playable_ = true;
      return std::string("; playing the bundled \"") + presets[candidate.bundled].name +
             "\" until a preset that builds is chosen";
    } catch (const std::exception&) {
      continue;  // the next (at this rate some presets cannot be built)
    }
  }
  return "; no bundled preset builds at " + std::to_string(std::lround(refused.sampleRate)) +
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
    sampleRate_ = sampleRate;
    stopping_ = false;
    recipe = attempted_ = wanted();
    playable_ = false;  // deactivate freed what played
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
      status_.store(outcome_.load(std::memory_order_acquire), std::memory_order_release);
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
