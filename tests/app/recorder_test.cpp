// The recorder meeting a write error (a full disk): the recording stops, the sound does not (the
// ring keeps being emptied), nothing throws or aborts, and finish() leaves either a valid WAV of
// what was written before the error or no file at all — never a temporary; and a recording of
// nothing leaves the path as it was.
#include "recorder.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sndfile.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "support/scratch_dir.h"
#include "support/tiny_disk.h"

namespace hamiltone::app {
namespace {

namespace fs = std::filesystem;

constexpr int kRate = 48000;
constexpr size_t kBlock = 480;  // frames the audio thread pushes at once

class RecorderTest : public ::testing::Test {
 protected:
  // Frame i of a stereo test signal: distinct channels, well inside full scale.
  static float sample(size_t i, int channel) {
    const double phase = 2.0 * 3.141592653589793 * 441.0 * static_cast<double>(i) / kRate;
    return static_cast<float>(channel == 0 ? 0.5 * std::sin(phase) : 0.25 * std::cos(phase));
  }

  // Pushes frames [from, from + count) as the audio thread would, a block at a time; a block the
  // ring has no room for is retried (the writer empties it every 10 ms) up to a generous bound.
  // Returns whether every block went in.
  static bool push(Recorder& recorder, size_t from, size_t count) {
    std::vector<float> block(2 * kBlock);
    for (size_t f = from; f < from + count; f += kBlock) {
      for (size_t i = 0; i < kBlock; ++i)
        for (int c = 0; c < 2; ++c) block[2 * i + c] = sample(f + i, c);
      for (int tries = 0; !recorder.ring().pushAll(block.data(), block.size()); ++tries) {
        if (tries == 20000) return false;
        std::this_thread::sleep_for(std::chrono::microseconds(500));
      }
    }
    return true;
  }

  static bool waitUntilFailed(const Recorder& recorder) {
    for (int tries = 0; tries < 20000 && !recorder.failed(); ++tries)
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    return recorder.failed();
  }

  std::vector<std::string> listing(const fs::path& dir) const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
    return names;
  }

  hamiltone::testing::ScratchDir scratch_{"hamiltone-recorder"};
  const fs::path dir_ = scratch_.path();
};

// Writes to the file `recorder` is writing fail as on a full disk from now on: the descriptor of
// its temporary (found through /proc/self/fd) becomes /dev/full.
bool makeFull(const Recorder& recorder) {
  const std::string prefix = recorder.path() + ".tmp-";
  for (const auto& entry : fs::directory_iterator("/proc/self/fd")) {
    std::error_code error;
    const fs::path target = fs::read_symlink(entry.path(), error);
    if (error || !target.string().starts_with(prefix)) continue;
    const int full = ::open("/dev/full", O_WRONLY);
    if (full < 0) return false;
    const bool ok = ::dup2(full, std::stoi(entry.path().filename())) >= 0;
    ::close(full);
    return ok;
  }
  return false;
}

// A 64 KiB disk fills after about 10 900 frames of 24-bit stereo: the file then holds exactly the
// frames written before, as a WAV libsndfile reads, each sample within one 24-bit step.
TEST_F(RecorderTest, AFullDiskStopsTheRecordingAndKeepsAValidWavOfWhatWasWritten) {
  const fs::path disk = dir_ / "disk";
  hamiltone::test::TinyDisk tiny(disk);
  if (!tiny.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  const fs::path take = disk / "take.wav";
  double seconds = 0.0;
  {
    Recorder recorder(take.string(), kRate);
    recorder.start();
    ASSERT_TRUE(push(recorder, 0, kRate));  // 1 s: more than the disk holds
    ASSERT_TRUE(waitUntilFailed(recorder));
    EXPECT_NE(recorder.error().find(take.string()), std::string::npos) << recorder.error();
    // The audio thread is never held up: twice the ring's capacity still goes through.
    EXPECT_TRUE(push(recorder, kRate, static_cast<size_t>(2 * Recorder::kRingSeconds * kRate)));
    seconds = recorder.finish();
    EXPECT_TRUE(recorder.kept()) << recorder.error();
    EXPECT_GT(seconds, 0.0);
    EXPECT_LT(seconds, 1.0);
    EXPECT_DOUBLE_EQ(seconds, recorder.failedAtSeconds());
  }
  EXPECT_EQ(listing(disk), std::vector<std::string>{"take.wav"});
  SF_INFO info{};
  SNDFILE* file = sf_open(take.c_str(), SFM_READ, &info);
  ASSERT_NE(file, nullptr) << sf_strerror(nullptr);
  EXPECT_EQ(info.format, SF_FORMAT_WAV | SF_FORMAT_PCM_24);
  EXPECT_EQ(info.frames, std::lround(seconds * kRate));
  std::vector<float> samples(static_cast<size_t>(2 * info.frames));
  EXPECT_EQ(sf_readf_float(file, samples.data(), info.frames), info.frames);
  sf_close(file);
  double worst = 0.0;
  for (size_t i = 0; i < samples.size(); ++i)
    worst = std::max(worst, std::abs(double(samples[i]) - sample(i / 2, static_cast<int>(i % 2))));
  EXPECT_LT(worst, std::ldexp(1.0, -23));  // 24-bit quantisation, rounding down (wav_writer.h)
  EXPECT_EQ(fs::file_size(take), 44u + 6u * static_cast<uintmax_t>(info.frames));  // no tail
}

// A file that cannot even be finalised (every write fails) is removed, with the reason: no file,
// no temporary, no exception.
TEST_F(RecorderTest, AFileThatCannotBeFinalisedIsRemoved) {
  const fs::path take = dir_ / "take.wav";
  {
    Recorder recorder(take.string(), kRate);
    ASSERT_TRUE(makeFull(recorder)) << "no /dev/full";
    recorder.start();
    ASSERT_TRUE(push(recorder, 0, kRate / 10));
    ASSERT_TRUE(waitUntilFailed(recorder));
    EXPECT_TRUE(
        push(recorder, kRate / 10, static_cast<size_t>(2 * Recorder::kRingSeconds * kRate)));
    EXPECT_EQ(recorder.finish(), 0.0);
    EXPECT_FALSE(recorder.kept());
    EXPECT_NE(recorder.error().find("take.wav"), std::string::npos) << recorder.error();
  }
  EXPECT_TRUE(listing(dir_).empty());
}

// --record take.flac is a FLAC file (24-bit), take.ogg an Ogg Vorbis one: what the extension says,
// as hamiltone-render's -o, where a WAV was written under any name.
TEST_F(RecorderTest, WritesTheTypeItsExtensionNames) {
  for (const auto& [name, type, format] :
       {std::tuple{"take.flac", cli::FileType::flac, SF_FORMAT_FLAC | SF_FORMAT_PCM_24},
        std::tuple{"take.ogg", cli::FileType::ogg, SF_FORMAT_OGG | SF_FORMAT_VORBIS}}) {
    const fs::path take = dir_ / name;
    {
      Recorder recorder(take.string(), kRate, type);
      recorder.start();
      ASSERT_TRUE(push(recorder, 0, kRate / 4));
      EXPECT_DOUBLE_EQ(recorder.finish(), 0.25) << name;
      EXPECT_TRUE(recorder.kept()) << recorder.error();
    }
    SF_INFO info{};
    SNDFILE* file = sf_open(take.c_str(), SFM_READ, &info);
    ASSERT_NE(file, nullptr) << name << ": " << sf_strerror(nullptr);
    EXPECT_EQ(info.format, format) << name;
    EXPECT_EQ(info.frames, kRate / 4) << name;
    EXPECT_EQ(info.channels, 2) << name;
    sf_close(file);
  }
}

// A recording of nothing (the stream never ran: the audio server went away as it started) does
// not replace the file at its path, nor leave a temporary; finish() from two threads at once
// (the stop signals' thread and the main one) finishes once and both see the same.
TEST_F(RecorderTest, ANothingRecordedLeavesTheFileAsItWas) {
  const fs::path take = dir_ / "take.wav";
  { std::ofstream(take) << "an earlier take"; }
  {
    Recorder recorder(take.string(), kRate);
    recorder.start();
    double other = -1.0;
    std::thread second([&] { other = recorder.finish(); });
    const double seconds = recorder.finish();
    second.join();
    EXPECT_EQ(seconds, 0.0);
    EXPECT_EQ(other, 0.0);
    EXPECT_TRUE(recorder.empty());
    EXPECT_FALSE(recorder.kept());
    EXPECT_FALSE(recorder.failed());
  }
  EXPECT_EQ(listing(dir_), std::vector<std::string>{"take.wav"});
  std::ifstream in(take);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "an earlier take");
}

}  // namespace
}  // namespace hamiltone::app
