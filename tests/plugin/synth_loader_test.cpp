// The plugin's loader: the presets compiled in are presets/'s files; every one builds at the rates
// hosts run at; overrides are read as --set takes them; a recipe is built at start() and, once
// running, whenever it changes, away from the caller; a refused one leaves nothing to take and
// says why (a bundled preset standing in when nothing played before); and what the audio thread
// gives back is taken only when the slot is free.
#include "synth_loader.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
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
  // The plugin's messages name its overrides, not hamiltone-render's --set, and a long piece of
  // junk by its start (a 1 MB one went whole into the host's log line).
  try {
    buildSynth({.overrides = "a4_Hz=1000"});
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("overrides: a4_Hz=1000"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("--set"), std::string::npos) << e.what();
  }
  try {
    buildSynth({.overrides = std::string(1 << 20, 'x')});
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_LT(std::string(e.what()).size(), 120u);
  }
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

// The Preset knob moved, while a preset plays, to one that cannot be built at the host's rate (the
// grand piano at 16 kHz): the preset before plays on, not another bundled one nobody chose.
TEST(SynthLoader, AKnobMovedToAPresetThatCannotBeBuiltLeavesTheOneBeforePlaying) {
  SynthLoader loader;
  loader.setBundled(3);
  loader.start(16000.0);
  ASSERT_EQ(loader.status(), LoadStatus::ready) << loader.error();
  std::unique_ptr<BuiltSynth> gong(loader.take());
  ASSERT_TRUE(gong);
  loader.setBundled(0);
  ASSERT_EQ(settled(loader), LoadStatus::failed);
  EXPECT_EQ(loader.take(), nullptr);
  EXPECT_NE(loader.error().find("the instrument before plays on"), std::string::npos)
      << loader.error();
  loader.stop();
}

// A session restored where its preset file is gone: nothing played before, so the bundled preset
// the Preset parameter names plays instead of silence, and the error says both.
TEST(SynthLoader, ARefusedFirstRecipeLeavesABundledPresetToPlay) {
  SynthLoader loader;
  loader.setBundled(2);
  loader.setFile("/nonexistent/session/preset.toml");
  loader.start(48000.0);
  EXPECT_EQ(loader.status(), LoadStatus::failed);
  std::unique_ptr<BuiltSynth> standIn(loader.take());
  ASSERT_TRUE(standIn);
  EXPECT_EQ(standIn->recipe, (SynthRecipe{.bundled = 2, .sampleRate = 48000.0}));
  const std::string error = loader.error();
  EXPECT_NE(error.find("/nonexistent/session/preset.toml"), std::string::npos) << error;
  EXPECT_NE(error.find(std::string("playing the bundled \"") + bundledPresets()[2].name),
            std::string::npos)
      << error;

  // The file still unreadable, overrides that do not parse: the same stand-in, not built again
  // (a swap would cut its notes).
  loader.setOverrides("bogus.key=1");
  ASSERT_EQ(settled(loader), LoadStatus::failed);
  EXPECT_EQ(loader.take(), nullptr);
  EXPECT_NE(loader.error().find("/nonexistent/session/preset.toml"), std::string::npos)
      << loader.error();
  EXPECT_NE(loader.error().find(std::string("playing the bundled \"") + bundledPresets()[2].name),
            std::string::npos)
      << loader.error();
  // The Preset knob is the way out in a host that shows no strings: it chooses the stand-in.
  loader.setBundled(4);
  ASSERT_EQ(settled(loader), LoadStatus::failed);
  std::unique_ptr<BuiltSynth> chosen(loader.take());
  ASSERT_TRUE(chosen);
  EXPECT_EQ(chosen->recipe, (SynthRecipe{.bundled = 4, .sampleRate = 48000.0}));

  // The file cleared, the overrides still refused: the stand-in plays on. Then the overrides
  // cleared: the recipe is the stand-in's own, so nothing is built (a swap would cut its notes)
  // and the refusal is over.
  loader.setFile("");
  ASSERT_EQ(settled(loader), LoadStatus::failed);
  EXPECT_EQ(loader.take(), nullptr);
  loader.setOverrides("");
  ASSERT_EQ(settled(loader), LoadStatus::ready);
  std::this_thread::sleep_for(std::chrono::milliseconds(5 * SynthLoader::kPollMs));
  EXPECT_EQ(loader.take(), nullptr);
  EXPECT_EQ(loader.error(), "");

  // A new start() (the host activating again) has nothing playing: it stands in again.
  loader.stop();
  loader.setFile("/nonexistent/session/preset.toml");
  loader.start(44100.0);
  std::unique_ptr<BuiltSynth> again(loader.take());
  ASSERT_TRUE(again);
  EXPECT_EQ(again->recipe, (SynthRecipe{.bundled = 4, .sampleRate = 44100.0}));
  loader.stop();
}

// At a rate the grand pianos cannot be built at (under 22.05 kHz), the first bundled preset that
// builds stands in; an index out of range is read as the first.
TEST(SynthLoader, TheStandInIsTheFirstBundledPresetThatBuildsAtTheRate) {
  SynthLoader loader;
  loader.setBundled(99);
  loader.start(16000.0);
  EXPECT_EQ(loader.status(), LoadStatus::failed);
  std::unique_ptr<BuiltSynth> standIn(loader.take());
  ASSERT_TRUE(standIn);
  int firstThatBuilds = -1;
  for (int i = 0; i < static_cast<int>(bundledPresets().size()) && firstThatBuilds < 0; ++i) {
    try {
      buildSynth({.bundled = i, .sampleRate = 16000.0});
      firstThatBuilds = i;
    } catch (const std::exception&) {
    }
  }
  ASSERT_GT(firstThatBuilds, 0) << "the grand piano builds at 16 kHz: the test needs another rate";
  EXPECT_EQ(standIn->recipe, (SynthRecipe{.bundled = firstThatBuilds, .sampleRate = 16000.0}));
  EXPECT_NE(loader.error().find("preset 99"), std::string::npos) << loader.error();
  loader.stop();
}

// While a preset file plays, it wins over the Preset knob: moving the knob builds nothing (it
// rebuilt the same file and swapped it in, cutting every note).
TEST(SynthLoader, ThePresetKnobBuildsNothingWhileAFilePlays) {
  const std::string file = ::testing::TempDir() + "loader-gong.toml";
  std::ofstream(file) << slurp(std::string(HAMILTONE_SOURCE_DIR) + "/presets/gong.toml");
  SynthLoader loader;
  loader.setFile(file);
  loader.start(48000.0);
  ASSERT_EQ(loader.status(), LoadStatus::ready) << loader.error();
  std::unique_ptr<BuiltSynth> built(loader.take());
  ASSERT_TRUE(built);
  EXPECT_EQ(built->recipe.file, file);
  loader.setBundled(5);
  EXPECT_EQ(settled(loader), LoadStatus::ready);
  std::this_thread::sleep_for(std::chrono::milliseconds(5 * SynthLoader::kPollMs));
  EXPECT_EQ(loader.take(), nullptr);
  loader.setFile("");  // the file cleared: the knob's preset is built
  ASSERT_EQ(settled(loader), LoadStatus::ready);
  std::unique_ptr<BuiltSynth> knob(loader.take());
  ASSERT_TRUE(knob);
  EXPECT_EQ(knob->recipe, (SynthRecipe{.bundled = 5, .sampleRate = 48000.0}));
  loader.stop();
  std::remove(file.c_str());
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
