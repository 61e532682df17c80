// WavWriter: what libsndfile reads back is what was written, to the format's quantisation step
// (FLAC's too; Ogg Vorbis's, lossy, near it); bad samples come back sanitised; no file, whole or
// partial, is left unless committed; and the extension of a path names its type.
#include "wav_writer.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sndfile.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "support/riff_chunks.h"
#include "support/scratch_dir.h"
#include "usage_error.h"

namespace {

namespace fs = std::filesystem;
using hamiltone::cli::FileType;
using hamiltone::cli::fileTypeOf;
using hamiltone::cli::SampleFormat;
using hamiltone::cli::UsageError;
using hamiltone::cli::WavWriter;

struct Sound {
  SF_INFO info{};
  std::vector<float> samples;  // interleaved
};

Sound readBack(const fs::path& path) {
  Sound sound;
  SNDFILE* file = sf_open(path.c_str(), SFM_READ, &sound.info);
  if (!file) throw std::runtime_error(std::string("cannot read back: ") + sf_strerror(nullptr));
  sound.samples.resize(static_cast<std::size_t>(sound.info.frames * sound.info.channels));
  const sf_count_t read = sf_readf_float(file, sound.samples.data(), sound.info.frames);
  sf_close(file);
  if (read != sound.info.frames) throw std::runtime_error("short read");
  return sound;
}

// The files in `dir`: after a failure there must be none, not even a temporary.
std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  return names;
}

// The descriptor this process holds on path's temporary (PATH.tmp-PID-XXXXXX); -1 if none.
int temporaryDescriptor(const fs::path& path) {
  for (const auto& entry : fs::directory_iterator("/proc/self/fd")) {
    std::error_code error;
    const std::string target = fs::read_symlink(entry.path(), error).string();
    if (!error && target.rfind(path.string() + ".tmp-", 0) == 0)
      return std::stoi(entry.path().filename().string());
  }
  return -1;
}

// A 440 Hz tone, interleaved; the channels differ (sine, half-amplitude cosine) so a swapped
// interleave shows.
std::vector<float> testTone(std::size_t frames, int rate, int channels) {
  std::vector<float> signal(frames * static_cast<std::size_t>(channels));
  for (std::size_t i = 0; i < frames; ++i) {
    const double phase = 2.0 * std::numbers::pi * 440.0 * static_cast<double>(i) / rate;
    signal[i * channels] = static_cast<float>(0.8 * std::sin(phase));
    if (channels == 2) signal[i * 2 + 1] = static_cast<float>(0.5 * std::cos(phase));
  }
  return signal;
}

class WavWriterTest : public ::testing::Test {
 protected:
  fs::path wav() const { return dir_ / "out.wav"; }

  hamiltone::testing::ScratchDir scratch_{"hamiltone-wav"};
  const fs::path dir_ = scratch_.path();
};

// Round trips at both common rates, in every format, mono and stereo.
class WavRoundTrip : public WavWriterTest,
                     public ::testing::WithParamInterface<std::tuple<int, SampleFormat, int>> {};

TEST_P(WavRoundTrip, ReadsBackWhatWasWrittenToTheQuantisationStep) {
  const auto [rate, format, channels] = GetParam();
  // 10007 frames in two calls, the second longer than the writer's 4096-frame chunk, so the
  // chunking and the joins are exercised.
  const std::size_t frames = 10007;
  const std::vector<float> signal = testTone(frames, rate, channels);
  {
    WavWriter writer(wav().string(), "-o", rate, channels, format);
    writer.write(signal.data(), 3000);
    writer.write(signal.data() + 3000 * channels, frames - 3000);
    writer.commit();
  }

  const Sound sound = readBack(wav());
  EXPECT_EQ(sound.info.samplerate, rate);
  EXPECT_EQ(sound.info.channels, channels);
  EXPECT_EQ(sound.info.frames, static_cast<sf_count_t>(frames));
  const int subformat = format == SampleFormat::pcm16   ? SF_FORMAT_PCM_16
                        : format == SampleFormat::pcm24 ? SF_FORMAT_PCM_24
                                                        : SF_FORMAT_FLOAT;
  EXPECT_EQ(sound.info.format, SF_FORMAT_WAV | subformat);

  // A quantiser is off by less than one step: libsndfile 1.2.0 with clipping on scales by 2^15
  // or 2^23 and rounds down (measured), and reading divides by the same power of two exactly.
  // A 32-bit float is stored as it is.
  const double step = format == SampleFormat::pcm16   ? std::ldexp(1.0, -15)
                      : format == SampleFormat::pcm24 ? std::ldexp(1.0, -23)
                                                      : 0.0;
  ASSERT_EQ(sound.samples.size(), signal.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < signal.size(); ++i)
    worst = std::max(worst, std::abs(double(sound.samples[i]) - double(signal[i])));
  if (format == SampleFormat::float32)
    EXPECT_EQ(worst, 0.0);
  else
    EXPECT_LT(worst, step);
}

INSTANTIATE_TEST_SUITE_P(RatesFormatsChannels, WavRoundTrip,
                         ::testing::Combine(::testing::Values(44100, 48000),
                                            ::testing::Values(SampleFormat::pcm16,
                                                              SampleFormat::pcm24,
                                                              SampleFormat::float32),
                                            ::testing::Values(1, 2)));

// The same samples give the same bytes, in every format: no chunk carries the time of writing
// (libsndfile's PEAK chunk, added to float files by default, does; its zero-filled PAD chunk, which
// aligns the data, does not). Two files written within one second agree even with a time stamp,
// so the chunk list is what tells.
TEST_F(WavWriterTest, SameSamplesGiveTheSameBytesInEveryFormat) {
  const std::vector<float> samples = {0.0f, 0.5f, -0.25f, 1.0f, -1.0f, 0.125f};
  for (const SampleFormat format :
       {SampleFormat::pcm16, SampleFormat::pcm24, SampleFormat::float32}) {
    std::string bytes[2];
    for (std::string& b : bytes) {
      WavWriter writer(wav().string(), "-o", 48000, 2, format);
      writer.write(samples.data(), samples.size() / 2);
      writer.commit();
      b = hamiltone::testing::fileBytes(wav());
    }
    const int f = static_cast<int>(format);
    EXPECT_EQ(bytes[0], bytes[1]) << "format " << f;
    for (const std::string& id : hamiltone::testing::riffChunkIds(bytes[0]))
      EXPECT_TRUE(id == "fmt " || id == "fact" || id == "PAD " || id == "data")
          << "format " << f << ": chunk \"" << id << "\"";
    EXPECT_EQ(hamiltone::testing::riffChunkIds(bytes[0]).back(), "data") << "format " << f;
  }
}

// NaN and ±Inf become silence, the rest is clamped to full scale.
const std::vector<float> kBadSamples = {std::numeric_limits<float>::quiet_NaN(),
                                        std::numeric_limits<float>::infinity(),
                                        -std::numeric_limits<float>::infinity(),
                                        1.5f,
                                        -2.0f,
                                        1.0f,
                                        -1.0f,
                                        0.25f};
const std::vector<float> kSanitised = {0.0f, 0.0f, 0.0f, 1.0f, -1.0f, 1.0f, -1.0f, 0.25f};

TEST_F(WavWriterTest, FloatFileHoldsSanitisedSamplesExactly) {
  WavWriter writer(wav().string(), "-o", 48000, 1, SampleFormat::float32);
  writer.write(kBadSamples.data(), kBadSamples.size());
  writer.commit();
  EXPECT_EQ(readBack(wav()).samples, kSanitised);
}

TEST_F(WavWriterTest, PcmFileSaturatesInsteadOfWrapping) {
  WavWriter writer(wav().string(), "-o", 48000, 2, SampleFormat::pcm16);
  writer.write(kBadSamples.data(), kBadSamples.size() / 2);
  writer.commit();
  const Sound sound = readBack(wav());
  ASSERT_EQ(sound.samples.size(), kSanitised.size());
  // +1 saturates at the largest code, 1 - 2^-15: one step short, the largest error allowed.
  for (std::size_t i = 0; i < kSanitised.size(); ++i)
    EXPECT_NEAR(sound.samples[i], kSanitised[i], std::ldexp(1.0, -15)) << "sample " << i;
}

TEST_F(WavWriterTest, ExceptionBeforeCommitLeavesNoFileAndNoTemporary) {
  try {
    WavWriter writer(wav().string(), "-o", 44100, 2, SampleFormat::pcm24);
    writer.write(kSanitised.data(), kSanitised.size() / 2);
    throw std::runtime_error("the render failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_TRUE(listing(dir_).empty());
}

TEST_F(WavWriterTest, UncommittedWriterLeavesAnExistingFileUntouched) {
  std::ofstream(wav()) << "the previous take";
  { WavWriter writer(wav().string(), "-o", 44100, 1, SampleFormat::pcm16); }
  std::stringstream kept;
  kept << std::ifstream(wav()).rdbuf();
  EXPECT_EQ(kept.str(), "the previous take");
  EXPECT_EQ(listing(dir_).size(), 1u);
}

TEST_F(WavWriterTest, CommitReplacesAnExistingFile) {
  std::ofstream(wav()) << "the previous take";
  WavWriter writer(wav().string(), "-o", 44100, 1, SampleFormat::pcm16);
  writer.write(kSanitised.data(), kSanitised.size());
  writer.commit();
  EXPECT_EQ(readBack(wav()).info.frames, static_cast<sf_count_t>(kSanitised.size()));
  EXPECT_EQ(listing(dir_).size(), 1u);
}

// The disk fills as the file is closed: the encoders' last blocks (FLAC, Vorbis) or the header
// (WAV) cannot be written. libsndfile's FLAC and Vorbis encoders report success then (a render
// exited 0 with a truncated FLAC); commit() must throw, naming the file and the system's error,
// and leave nothing. The temporary's descriptor is made /dev/full after the samples are written.
TEST_F(WavWriterTest, AWriteThatFailsAsTheFileClosesLeavesNoFile) {
  const int full = ::open("/dev/full", O_WRONLY);
  if (full < 0) GTEST_SKIP() << "no /dev/full";
  const std::vector<float> tone = testTone(4000, 48000, 1);
  for (const auto& [name, type, format] :
       {std::tuple{"out.wav", FileType::wav, SampleFormat::pcm16},
        std::tuple{"out.flac", FileType::flac, SampleFormat::pcm16},
        std::tuple{"out.ogg", FileType::ogg, SampleFormat::pcm16}}) {
    const fs::path path = dir_ / name;
    WavWriter writer(path.string(), "-o", 48000, 1, format, type);
    writer.write(tone.data(), tone.size());
    ASSERT_GE(::dup2(full, temporaryDescriptor(path)), 0) << name;
    try {
      writer.commit();
      ADD_FAILURE() << name << ": committed a file whose last write failed";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(std::strerror(ENOSPC)), std::string::npos) << e.what();
    }
  }
  ::close(full);
  EXPECT_TRUE(listing(dir_).empty());
}

TEST_F(WavWriterTest, SignalRemovesTheTemporary) {
  // The child dies by SIGTERM mid-write; atomic_file's handler unlinks the temporary and exits
  // with 128 + 15, as a shell reports a killed process.
  EXPECT_EXIT(
      {
        WavWriter writer(wav().string(), "-o", 44100, 1, SampleFormat::pcm16);
        writer.write(kSanitised.data(), kSanitised.size());
        std::raise(SIGTERM);
      },
      ::testing::ExitedWithCode(128 + SIGTERM), "");
  EXPECT_TRUE(listing(dir_).empty());
}

TEST_F(WavWriterTest, MissingDirectoryIsAUsageErrorNamingFlagAndPath) {
  const std::string path = (dir_ / "no-such-dir" / "out.wav").string();
  try {
    WavWriter writer(path, "-o", 44100, 1, SampleFormat::pcm16);
    FAIL() << "expected UsageError";
  } catch (const UsageError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("-o = " + path), std::string::npos) << message;
    EXPECT_NE(message.find("cannot write there"), std::string::npos) << message;
  }
}

TEST_F(WavWriterTest, ReadOnlyDirectoryIsAUsageErrorNamingThePath) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into a read-only directory";
  fs::permissions(dir_, fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write,
                  fs::perm_options::remove);
  EXPECT_THROW(
      {
        try {
          WavWriter writer(wav().string(), "-o", 44100, 1, SampleFormat::pcm16);
        } catch (const UsageError& e) {
          EXPECT_NE(std::string(e.what()).find(wav().string()), std::string::npos) << e.what();
          throw;
        }
      },
      UsageError);
}

TEST_F(WavWriterTest, DirectoryAndDeviceAreRefused) {
  EXPECT_THROW(WavWriter(dir_.string(), "-o", 44100, 1, SampleFormat::pcm16), UsageError);
  EXPECT_THROW(WavWriter("/dev/null", "-o", 44100, 1, SampleFormat::pcm16), UsageError);
  EXPECT_THROW(WavWriter("", "-o", 44100, 1, SampleFormat::pcm16), UsageError);
}

TEST_F(WavWriterTest, BadLayoutIsRefusedBeforeATemporaryIsMade) {
  EXPECT_THROW(WavWriter(wav().string(), "-o", 44100, 3, SampleFormat::pcm16),
               std::invalid_argument);
  EXPECT_THROW(WavWriter(wav().string(), "-o", 0, 1, SampleFormat::pcm16), std::invalid_argument);
  EXPECT_TRUE(listing(dir_).empty());
}

// FLAC is lossless: the samples come back to the PCM step, as from a WAV. Ogg Vorbis is lossy:
// the tone's RMS comes back within 1 % per channel (measured: 0.1 % at Vorbis's default quality),
// and the frame count whole.
TEST_F(WavWriterTest, FlacAndOggHoldTheSignal) {
  const std::vector<float> signal = testTone(48000, 48000, 2);
  for (const FileType type : {FileType::flac, FileType::ogg}) {
    const fs::path path = dir_ / (type == FileType::flac ? "out.flac" : "out.ogg");
    {
      WavWriter writer(path.string(), "-o", 48000, 2, SampleFormat::pcm24, type);
      writer.write(signal.data(), 48000);
      writer.commit();
    }
    const Sound sound = readBack(path);
    EXPECT_EQ(sound.info.format & SF_FORMAT_TYPEMASK,
              type == FileType::flac ? SF_FORMAT_FLAC : SF_FORMAT_OGG);
    ASSERT_EQ(sound.info.frames, 48000);
    if (type == FileType::flac) {
      double worst = 0.0;
      for (std::size_t i = 0; i < signal.size(); ++i)
        worst = std::max(worst, std::abs(double(sound.samples[i]) - double(signal[i])));
      EXPECT_LT(worst, std::ldexp(1.0, -23));
      continue;
    }
    for (int c = 0; c < 2; ++c) {
      double written = 0.0, read = 0.0;
      for (std::size_t i = c; i < signal.size(); i += 2) {
        written += double(signal[i]) * signal[i];
        read += double(sound.samples[i]) * sound.samples[i];
      }
      EXPECT_NEAR(std::sqrt(read / written), 1.0, 0.01) << "channel " << c;
    }
  }
}

TEST_F(WavWriterTest, FlacRefusesFloatSamples) {
  EXPECT_THROW(WavWriter((dir_ / "out.flac").string(), "-o", 48000, 2, SampleFormat::float32,
                         FileType::flac),
               std::invalid_argument);
  EXPECT_TRUE(listing(dir_).empty());
}

TEST(FileType, TheExtensionNamesItInAnyCaseAndOthersAreRefusedListingTheValidOnes) {
  EXPECT_EQ(fileTypeOf("a/b.wav", "-o"), FileType::wav);
  EXPECT_EQ(fileTypeOf("b.WAV", "-o"), FileType::wav);
  EXPECT_EQ(fileTypeOf("b.flac", "-o"), FileType::flac);
  EXPECT_EQ(fileTypeOf("b.Ogg", "-o"), FileType::ogg);
  for (const auto& [path, why] :
       {std::pair{"take.mp3", ".mp3 is not a format hamiltone can write"},
        std::pair{"take", "no extension"}, std::pair{"take.wav.tmp", ".tmp is not a format"}}) {
    try {
      fileTypeOf(path, "-o");
      ADD_FAILURE() << path << " was accepted";
    } catch (const UsageError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find(std::string("-o ") + path + ": " + why), 0u) << message;
      EXPECT_NE(message.find(".wav, .flac or .ogg"), std::string::npos) << message;
    }
  }
}

TEST_F(WavWriterTest, WriteAfterCommitIsALogicError) {
  WavWriter writer(wav().string(), "-o", 44100, 1, SampleFormat::float32);
  writer.commit();
  EXPECT_THROW(writer.write(kSanitised.data(), 1), std::logic_error);
  EXPECT_EQ(readBack(wav()).info.frames, 0);
}

}  // namespace
