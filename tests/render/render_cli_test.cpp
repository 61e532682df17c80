// hamiltone-render as a user meets it: the WAV it writes (rate, channels, format, length), the
// pitch of rendered notes measured from the file, and bad input refused with no file written.
#include <gtest/gtest.h>
#include <sndfile.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "support/midi_writer.h"
#include "support/riff_chunks.h"
#include "support/run_command.h"
#include "support/scratch_dir.h"
#include "support/spectrum.h"
#include "support/tiny_disk.h"

namespace {

namespace fs = std::filesystem;

using Result = hamiltone::testing::CommandResult;

struct Wav {
  SF_INFO info{};
  std::vector<float> samples;  // interleaved
};

class RenderCli : public ::testing::Test {
 protected:
  Result run(const std::string& args) {
    return hamiltone::testing::runCommand(std::string(HAMILTONE_RENDER) + " " + args,
                                          dir_ / "stderr");
  }

  static Wav read(const fs::path& path) {
    Wav wav;
    SNDFILE* f = sf_open(path.c_str(), SFM_READ, &wav.info);
    if (!f) return wav;
    wav.samples.resize(static_cast<size_t>(wav.info.frames * wav.info.channels));
    sf_readf_float(f, wav.samples.data(), wav.info.frames);
    sf_close(f);
    return wav;
  }

  std::string wav() const { return (dir_ / "out.wav").string(); }

  // Exit 2, the message mentions `mention`, and neither the WAV nor a temporary is left.
  void expectRefused(const std::string& args, const std::string& mention) {
    const Result r = run(args + " -o " + wav());
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << args << "\nstderr: " << r.err;
    for (const auto& entry : fs::directory_iterator(dir_))  // the inputs may be there, no WAV
      EXPECT_EQ(entry.path().filename().string().find("out.wav"), std::string::npos) << args;
  }

  hamiltone::testing::ScratchDir scratch_{"hamiltone-render"};
  const fs::path dir_ = scratch_.path();
};

std::string preset(const char* name) {
  return std::string(HAMILTONE_SOURCE_DIR) + "/presets/" + name + ".toml";
}

// What hamiltone-render printed on standard output to a full disk was lost with exit code 0 (a
// listing, --help, a summary): now exit 1, saying so, as for hamiltone-sim and hamiltone-play
// (cli/standard_output.h; PlayCli has its own case). The group's own redirection would otherwise
// send stdout to /dev/null: the inner one is the program's.
TEST_F(RenderCli, AStandardOutputThatCannotBeWrittenIsAnIoError) {
  for (const std::string& program : {std::string(HAMILTONE_RENDER) + " --list-params",
                                     std::string(HAMILTONE_RENDER) + " --help"}) {
    const Result r =
        hamiltone::testing::runCommand("{ " + program + " >/dev/full; }", dir_ / "stderr");
    EXPECT_EQ(r.exitCode, 1) << program << "\n" << r.err;
    EXPECT_NE(r.err.find("writing to standard output failed"), std::string::npos) << r.err;
  }
}

TEST_F(RenderCli, WritesTheRequestedRateChannelsFormatAndLength) {
  const Result r = run("--preset " + preset("paper-c3-string") +
                       " --notes C3:100:0.5 --tail 0.25 --sample-rate 44100 --format pcm16 "
                       "--quiet -o " +
                       wav());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err, "");  // --quiet
  const Wav w = read(wav());
  EXPECT_EQ(w.info.samplerate, 44100);
  EXPECT_EQ(w.info.channels, 2);
  EXPECT_EQ(w.info.format, SF_FORMAT_WAV | SF_FORMAT_PCM_16);
  EXPECT_EQ(w.info.frames, std::lround(0.75 * 44100));
  for (const char* format : {"pcm24", "float32"}) {
    ASSERT_EQ(run("--preset " + preset("paper-c3-string") + " --notes C3 --tail 0 --format " +
                  format + " -o " + wav())
                  .exitCode,
              0);
    const Wav f = read(wav());
    EXPECT_EQ(f.info.format & SF_FORMAT_SUBMASK,
              std::string(format) == "pcm24" ? SF_FORMAT_PCM_24 : SF_FORMAT_FLOAT);
    EXPECT_EQ(f.info.frames, 48000);
  }
}

// The same command twice gives the same file, byte for byte, in every format: the chunks are
// the format, (for float) the frame count, zero padding and the samples — nothing that records
// when.
TEST_F(RenderCli, TwoRendersAreTheSameBytesInEveryFormat) {
  for (const char* format : {"pcm16", "pcm24", "float32"}) {
    std::string bytes[2];
    for (std::string& b : bytes) {
      const Result r =
          run("--preset " + preset("paper-c3-string") +
              " --notes C3:100:0.1 --tail 0 --quiet --format " + format + " -o " + wav());
      ASSERT_EQ(r.exitCode, 0) << r.err;
      b = hamiltone::testing::fileBytes(wav());
    }
    EXPECT_EQ(bytes[0], bytes[1]) << format;
    const std::vector<std::string> ids = hamiltone::testing::riffChunkIds(bytes[0]);
    ASSERT_FALSE(ids.empty()) << format;
    for (const std::string& id : ids)
      EXPECT_TRUE(id == "fmt " || id == "fact" || id == "PAD " || id == "data")
          << format << ": chunk " << id;
  }
}

// The keys render on the threads asked for, each into its own buffer, summed in a fixed order: a
// MIDI file with a chord, the pedal, restrikes, steals (--voices 3), program changes between the
// piano and the cymbal and a bend gives the same float32 file on 1, 2 and 3 threads (3: more than
// the 2 cores CI has), and in blocks of 100 frames the events also split blocks into pieces.
TEST_F(RenderCli, TheFileIsTheSameBitsWhateverTheThreads) {
  using hamiltone::testing::TrackWriter;
  TrackWriter track;  // 480 ticks a quarter at 120 bpm: 96 ticks are 0.1 s
  track.event(0, {0x90, 48, 100}).event(0, {0x90, 52, 80}).event(0, {0x90, 55, 90});
  track.event(96, {0xB0, 64, 127}).event(96, {0x80, 48, 0}).event(0, {0x80, 52, 0});
  track.event(96, {0x90, 48, 127}).event(48, {0x90, 60, 70}).event(96, {0x90, 64, 110});
  track.event(96, {0xC0, 1}).event(0, {0x90, 60, 100}).event(96, {0x90, 62, 90});
  track.event(96, {0xB0, 64, 0}).event(96, {0xC0, 0}).event(0, {0x90, 55, 60});
  track.event(96, {0xE0, 0, 80}).event(144, {0xB0, 123, 0}).endOfTrack(96);
  const hamiltone::testing::Bytes file = hamiltone::testing::midiFile(0, 480, {track});
  const fs::path midi = dir_ / "score.mid";
  std::ofstream(midi, std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  std::string bytes[3];
  for (int threads = 1; threads <= 3; ++threads) {
    const Result r = run("--preset " + preset("grand-piano") + " --preset " +
                         preset("small-cymbal") + " --midi " + midi.string() +
                         " --voices 3 --block 100 --tail 0.3 --format float32 --quiet --threads " +
                         std::to_string(threads) + " -o " + wav());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    bytes[threads - 1] = hamiltone::testing::fileBytes(wav());
  }
  ASSERT_GT(read(wav()).info.frames, 48000);
  EXPECT_TRUE(bytes[1] == bytes[0]) << "2 threads differ from 1";
  EXPECT_TRUE(bytes[2] == bytes[0]) << "3 threads differ from 1";
}

// C3, A4 and C6 of the grand piano, played softly (little pitch glide), measured from the file:
// on rigid ends (grand-piano-strings) the unison strings sit symmetrically around the note, so the
// peak of their sum is on it; on the bridge (grand-piano) a single string is, its reactance moving
// it by Z0 X / (π |Z|²) of its frequency, under a fifth of a cent. (Three detuned strings on the
// bridge are not: once their in-phase part has drained, what rings is nearer the outer strings.)
TEST_F(RenderCli, RenderedNotesAreInTuneWithinOneCent) {
  const struct {
    const char* name;
    double hz;
  } notes[] = {{"C3", 130.8128}, {"A4", 440.0}, {"C6", 1046.502}};
  for (const auto& note : notes)
    for (const std::string& piano :
         {" --preset " + preset("grand-piano-strings"),
          " --preset " + preset("grand-piano") + " --set string.unisons=1"}) {
      const Result r = run(piano + " --notes " + note.name + ":30:2 --tail 0 --quiet -o " + wav());
      ASSERT_EQ(r.exitCode, 0) << r.err;
      const Wav w = read(wav());
      std::vector<double> left;
      for (sf_count_t i = 24000; i < w.info.frames; ++i) left.push_back(w.samples[2 * i]);
      const double measured = hamiltone::testing::peakFrequency(left, note.hz, 48000.0);
      EXPECT_NEAR(1200.0 * std::log2(measured / note.hz), 0.0, 1.0) << note.name << piano;
    }
}

TEST_F(RenderCli, PlaysTheBundledDemoMidiFile) {
  const Result r =
      run("--preset " + preset("paper-c3-string") + " --midi " +
          HAMILTONE_SOURCE_DIR "/presets/demo.mid --tail 0.5 --block 1000 -o " + wav());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("real-time factor"), std::string::npos) << r.err;
  const Wav w = read(wav());
  EXPECT_GT(w.info.frames, 10 * 48000);
}

TEST_F(RenderCli, RefusesBadInputAndWritesNothing) {
  const std::string c3 = " --preset " + preset("paper-c3-string");
  expectRefused(c3, "--midi");                                    // neither --midi nor --notes
  expectRefused(c3 + " --notes C3 --midi x.mid", "exactly one");  // both
  expectRefused(c3 + " --notes H3", "unknown note name");
  expectRefused(c3 + " --notes C3 --sample-rate 1000", "--sample-rate");
  expectRefused(c3 + " --notes C3 --tail -1", "--tail");
  expectRefused(c3 + " --notes C3 --voices 0", "--voices");
  expectRefused(c3 + " --notes C3 --block 0", "--block");
  expectRefused(c3 + " --notes C3 --threads 0", "--threads = 0: out of range");
  expectRefused(c3 + " --notes C3 --threads many", "--threads");
  expectRefused(c3 + " --midi " + (dir_ / "missing.mid").string(), "missing.mid");
  std::ofstream(dir_ / "junk.mid") << "MThd junk";
  expectRefused(c3 + " --midi " + (dir_ / "junk.mid").string(), "junk.mid");
  fs::remove(dir_ / "junk.mid");
  std::ofstream(dir_ / "bad.toml") << "model = \"string\"\nbogus_key = 1\n";
  expectRefused(" --preset " + (dir_ / "bad.toml").string() + " --notes C3", "bad.toml:2:1");
  fs::remove(dir_ / "bad.toml");
  // An unwritable output path fails before any work, naming -o.
  const Result r = run(c3 + " --notes C3 -o /proc/hamiltone/out.wav");
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("-o"), std::string::npos) << r.err;
}

// -o's extension chooses the format; another is refused naming it, before any work.
TEST_F(RenderCli, TheOutputExtensionChoosesTheFormat) {
  const std::string c3 = "--preset " + preset("paper-c3-string") + " --notes C3:100:0.2 --tail 0 ";
  for (const auto& [name, type] :
       {std::pair{"out.flac", SF_FORMAT_FLAC}, std::pair{"out.ogg", SF_FORMAT_OGG},
        std::pair{"out.WAV", SF_FORMAT_WAV}}) {
    const fs::path out = dir_ / name;
    const Result r = run(c3 + "--quiet -o " + out.string());
    ASSERT_EQ(r.exitCode, 0) << name << ": " << r.err;
    EXPECT_EQ(read(out).info.format & SF_FORMAT_TYPEMASK, type) << name;
  }
  const Result mp3 = run(c3 + "-o " + (dir_ / "out.mp3").string());
  EXPECT_EQ(mp3.exitCode, 2);
  EXPECT_NE(mp3.err.find("out.mp3: .mp3 is not a format hamiltone can write; the extension "
                         "chooses the format: .wav, .flac or .ogg"),
            std::string::npos)
      << mp3.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.mp3"));
  const Result flacFloat = run(c3 + "--format float32 -o " + (dir_ / "f.flac").string());
  EXPECT_EQ(flacFloat.exitCode, 2);
  EXPECT_NE(flacFloat.err.find("FLAC holds integer samples"), std::string::npos) << flacFloat.err;
}

// --set over every preset, heard in the file: A4 of the grand piano (its strings) tuned to a4_Hz =
// 432 (the preset tunes by tension) sounds at 432 Hz, within the cent the tuning test allows.
TEST_F(RenderCli, SetChangesWhatIsRendered) {
  const Result r = run("--preset " + preset("grand-piano-strings") +
                       " --set a4_Hz=432 --notes A4:30:2 --tail 0 --quiet -o " + wav());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Wav w = read(wav());
  std::vector<double> left;
  for (sf_count_t i = 24000; i < w.info.frames; ++i) left.push_back(w.samples[2 * i]);
  const double measured = hamiltone::testing::peakFrequency(left, 432.0, 48000.0);
  EXPECT_NEAR(1200.0 * std::log2(measured / 432.0), 0.0, 1.0);
}

TEST_F(RenderCli, RefusesABadSetNamingItAndWritesNothing) {
  const std::string c3 = " --preset " + preset("paper-c3-string") + " --notes C3";
  expectRefused(
      c3 + " --set scheme.oversampling=3",
      "paper-c3-string.toml: --set scheme.oversampling=3: expected one of 1, 2, 4, 8, 16, 32, 64");
  expectRefused(c3 + " --set scheme.grid_rule=diagonal",
                "--set scheme.grid_rule=diagonal: expected one of \"two-grid\", \"transverse\", "
                "\"longitudinal\"");
  expectRefused(c3 + " --set hammer.velocity_max_m_s=30",
                "--set hammer.velocity_max_m_s=30: out of range; expected 0 … 20");
  expectRefused(c3 + " --set scheme.oversampeling=16", "did you mean scheme.oversampling?");
  expectRefused(c3 + " --set plate.lx_m=1", "--set plate.lx_m=1: plate model only");
  expectRefused(c3 + " --set foo", "--set foo: expected NAME=VALUE");
  expectRefused(c3 + " --set =16", "--set =16: expected NAME=VALUE");
  // A voice the overrides make impossible: the grand piano's treble strings on the longitudinal
  // grid at the base rate.
  expectRefused(" --preset " + preset("grand-piano") +
                    " --notes C3 --set scheme.grid_rule=longitudinal --set scheme.oversampling=1",
                "(with --set scheme.grid_rule=longitudinal, --set scheme.oversampling=1)");
}

// -o naming an input (the MIDI file, a preset — by its path or through a link) would destroy it,
// and a symlink to nothing would create a file where the link points, or replace the link:
// each is refused before any work, naming -o, and every file is left as it was.
TEST_F(RenderCli, RefusesAnOutputThatIsAnInputOrADanglingSymlink) {
  const fs::path midi = dir_ / "in.mid", toml = dir_ / "in.toml", link = dir_ / "link.wav";
  fs::copy_file(HAMILTONE_SOURCE_DIR "/presets/demo.mid", midi);
  fs::copy_file(preset("paper-c3-string"), toml);
  const std::string midiBytes = hamiltone::testing::fileBytes(midi);
  const std::string tomlBytes = hamiltone::testing::fileBytes(toml);
  const auto expectRefusedOutput = [&](const std::string& args, const fs::path& out,
                                       const std::string& mention) {
    const Result r = run(args + " --quiet -o " + out.string());
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("-o = " + out.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
    EXPECT_EQ(hamiltone::testing::fileBytes(midi), midiBytes) << args;
    EXPECT_EQ(hamiltone::testing::fileBytes(toml), tomlBytes) << args;
  };
  expectRefusedOutput("--preset " + toml.string() + " --midi " + midi.string(), midi, "--midi");
  expectRefusedOutput("--preset " + toml.string() + " --notes C3", toml, "--preset");
  fs::create_symlink(toml, link);
  expectRefusedOutput("--preset " + toml.string() + " --notes C3", link, "--preset");
  fs::remove(link);
  fs::create_symlink(dir_ / "nowhere" / "x.wav", link);
  expectRefusedOutput("--preset " + toml.string() + " --notes C3", link, "does not exist");
  EXPECT_TRUE(fs::is_symlink(link));
  fs::remove(link);
  fs::create_symlink(dir_ / "missing.wav", link);
  expectRefusedOutput("--preset " + toml.string() + " --notes C3", link, "does not exist");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_FALSE(fs::exists(dir_ / "missing.wav"));
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 3u);  // the inputs and the link: no temporary
}

// A preset the guard has to silence renders noise, or silence, where notes were asked for: the
// output is known to be wrong, so none is written, the exit code is 2 (bad input) and the message
// names the preset and the parameter at fault. Here the gauge shift ε = 10⁶ J, far above the
// energies of a struck string (~10⁻² J), which with any check on ε at load gives the same result.
TEST_F(RenderCli, AnUnstablePresetIsAnErrorAndWritesNothing) {
  std::string text = hamiltone::testing::fileBytes(preset("paper-c3-string"));
  const std::string was = "epsilon_J = 0.0 ";
  ASSERT_NE(text.find(was), std::string::npos);
  text.replace(text.find(was), was.size(), "epsilon_J = 1e6 ");
  const fs::path unstable = dir_ / "unstable.toml";
  std::ofstream(unstable) << text;
  const Result r =
      run("--preset " + unstable.string() + " --notes C3:127:0.5 --tail 0 -o " + wav());
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("unstable.toml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("epsilon_J"), std::string::npos) << r.err;
  for (const auto& entry : fs::directory_iterator(dir_))  // the preset, no WAV, no temporary
    EXPECT_EQ(entry.path().filename().string().find("out.wav"), std::string::npos);
}

// --quiet drops the progress bar and the summary, not the warnings: a render whose only note the
// preset does not play is silent, and says so (under --quiet it once printed nothing, exit 0).
TEST_F(RenderCli, QuietStillWarnsOfUnplayedNotesAndASilentOutput) {
  const Result r = run("--preset " + preset("paper-c3-string") + " --notes G9:100:0.1 --tail 0.1" +
                       " --quiet -o " + wav());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("does not play MIDI note(s) 127"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the output is silent"), std::string::npos) << r.err;
}

// A MIDI file that changes to a program no --preset loaded is played on the preset in force, and
// the render says which programs it ignored and how to load them (it said nothing).
TEST_F(RenderCli, ProgramChangesToPresetsNotLoadedAreNamed) {
  using hamiltone::testing::TrackWriter;
  TrackWriter track;
  track.event(0, {0xC0, 4}).event(0, {0x90, 60, 80}).event(96, {0x80, 60, 0}).endOfTrack(0);
  const hamiltone::testing::Bytes file = hamiltone::testing::midiFile(0, 480, {track});
  const fs::path midi = dir_ / "programs.mid";
  std::ofstream(midi, std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  const Result r = run("--preset " + preset("small-cymbal") + " --midi " + midi.string() +
                       " --tail 0.1 --quiet -o " + wav());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("warning: program change to 4 is ignored: 1 preset is loaded (program 0)"),
            std::string::npos)
      << r.err;
}

// An option whose value was forgotten is refused naming it and the option after it (CLI11 took
// "--notes" as the preset and then refused the notes: "give exactly one of --midi FILE or --notes
// LIST").
TEST_F(RenderCli, AnOptionMissingItsValueIsNamed) {
  const Result r = run("--preset --notes C4:100:0.1 -o " + wav());
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("--preset is missing its value: the argument after it, --notes, is an "
                       "option"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(wav()));
}

// Ogg Vorbis holds rates up to 200 kHz: a higher one is refused before rendering, naming the rate
// and the formats that hold it (it failed at the first write, exit 1, "Format not recognised").
TEST_F(RenderCli, OggAboveItsHighestRateIsRefusedBeforeRendering) {
  const std::string ogg = (dir_ / "out.ogg").string();
  const Result r = run("--preset " + preset("paper-c3-string") +
                       " --notes C3:100:0.1 --sample-rate 200001 --quiet -o " + ogg);
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("200001"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("200000"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(".flac"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(ogg));
  EXPECT_EQ(run("--preset " + preset("paper-c3-string") +
                " --notes C3:100:0.1 --tail 0 --sample-rate 200000 --quiet -o " + ogg)
                .exitCode,
            0);
}

// A full disk is an I/O error: exit 1, the message names the file, and neither it nor a temporary
// is left (docs/failure-behaviour.md). 1 s of pcm24 stereo is 288 kB, more than the 64 KiB disk.
TEST_F(RenderCli, AFullDiskIsAnIoErrorAndLeavesNoFile) {
  const fs::path full = dir_ / "full";
  hamiltone::test::TinyDisk disk(full);
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a 64 KiB tmpfs here (needs root)";
  const fs::path out = full / "out.wav";
  const Result r = run("--preset " + preset("paper-c3-string") +
                       " --notes C3 --tail 0 --quiet -o " + out.string());
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find(out.string()), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(full));
}

TEST_F(RenderCli, ListsTheParameterTable) {
  const std::string out = (dir_ / "params.txt").string();
  const int status =
      std::system((std::string(HAMILTONE_RENDER) + " --list-params >" + out).c_str());
  ASSERT_EQ(WEXITSTATUS(status), 0);
  std::ifstream in(out);
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_NE(s.str().find("string.tension_N"), std::string::npos);
  EXPECT_NE(s.str().find("polyphony"), std::string::npos);
}

}  // namespace
