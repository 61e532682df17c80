// The plugin's loader: the presets compiled in are presets/'s files; every one builds at the rates
// hosts run at; overrides are read as --set takes them; a recipe is built at start() and, once
// running, whenever it changes, away from the caller; a refused one leaves nothing to take and
// says why; and what the audio thread gives back is taken only when the slot is free.
#include "synth_loader.h"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "bundled_presets.h"

namespace hamiltone::plugin {
namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The status once it is no longer "loading", within 30 s.
LoadStatus settled(const SynthLoader& loader) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (loader.status() == LoadStatus::loading && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return loader.status();
}

TEST(BundledPresets, AreThePresetFilesWithTheirNames) {
  const auto presets = bundledPresets();
  ASSERT_EQ(presets.size(), 7u);
  EXPECT_STREQ(presets[0].file, "grand-piano.toml");  // the default
  EXPECT_STREQ(presets[0].name, "Grand piano");
  for (const BundledPreset& p : presets)
    EXPECT_EQ(p.text, slurp(std::string(HAMILTONE_SOURCE_DIR) + "/presets/" + p.file)) << p.file;
}

TEST(BuildSynth, EveryBundledPresetBuildsAtTheCommonRates) {
  for (int i = 0; i < static_cast<int>(bundledPresets().size()); ++i)
    for (double rate : {44100.0, 48000.0, 88200.0, 96000.0}) {
      const std::unique_ptr<BuiltSynth> built = buildSynth({.bundled = i, .sampleRate = rate});
      EXPECT_EQ(built->synth.instruments().size(), 1u);
      EXPECT_EQ(built->recipe.sampleRate, rate);
    }
}

TEST(BuildSynth, OverridesAreReadAsSetTakesThemAndBadOnesSayWhy) {
  const auto built =
      buildSynth({.overrides = "a4_Hz=432;\n# tuning for the choir\n gain_dB = -1 "});
  EXPECT_EQ(built->synth.instruments()[0].gainDb, -1.0);
  EXPECT_EQ(built->synth.instruments()[0].keys[0].patch.a4Hz, 432.0);
  try {
    buildSynth({.overrides = "a4_Hz"});
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_STREQ(e.what(), "overrides: \"a4_Hz\": expected NAME=VALUE");
  }
  EXPECT_THROW(buildSynth({.overrides = "a4_Hz=1000"}), std::exception);
  EXPECT_THROW(buildSynth({.bundled = 7}), std::invalid_argument);
  EXPECT_THROW(buildSynth({.file = "/nonexistent/preset.toml"}), std::exception);
}

TEST(SynthLoader, StartBuildsNowAndChangesAreBuiltAwayFromTheCaller) {
  SynthLoader loader;
  loader.setBundled(1);
  EXPECT_EQ(loader.status(), LoadStatus::loading);
  loader.start(44100.0);
  EXPECT_EQ(loader.status(), LoadStatus::ready);
  std::unique_ptr<BuiltSynth> first(loader.take());
  ASSERT_TRUE(first);
  EXPECT_EQ(first->recipe, (SynthRecipe{.bundled = 1, .sampleRate = 44100.0}));
  EXPECT_EQ(loader.take(), nullptr);  // taken once

  loader.setBundled(0);
  EXPECT_EQ(loader.status(), LoadStatus::loading);  // at once, before anything is built
  ASSERT_EQ(settled(loader), LoadStatus::ready);
  std::unique_ptr<BuiltSynth> second(loader.take());
  ASSERT_TRUE(second);
  EXPECT_EQ(second->recipe.bundled, 0);

  loader.setOverrides("bogus.key=1");
  ASSERT_EQ(settled(loader), LoadStatus::failed);
  EXPECT_NE(loader.error().find("bogus.key"), std::string::npos) << loader.error();
  EXPECT_EQ(loader.take(), nullptr);  // nothing to take: the one playing plays on
  loader.setOverrides("");            // back to what was built last: its outcome, at once or soon
  EXPECT_EQ(settled(loader), LoadStatus::ready);
  loader.stop();
}

TEST(SynthLoader, WhatIsGivenBackWaitsForTheSlotAndIsFreedByTheLoader) {
  SynthLoader loader;
  loader.start(48000.0);
  BuiltSynth* built = loader.take();
  ASSERT_TRUE(built);
  EXPECT_TRUE(loader.giveBack(built));
  auto spare = buildSynth({});
  // Until the loader's thread has freed the first, the slot is taken.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  bool given = loader.giveBack(spare.get());
  while (!given && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(SynthLoader::kPollMs));
    given = loader.giveBack(spare.get());
  }
  ASSERT_TRUE(given);
  spare.release();  // the loader's now
  loader.stop();    // frees it
}

}  // namespace
}  // namespace hamiltone::plugin
