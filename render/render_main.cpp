// hamiltone-render: plays a MIDI file or a --notes list on presets and writes a WAV, FLAC or Ogg
// Vorbis file.
#include <CLI/App.hpp>
#include <CLI/Config.hpp>
#include <CLI/Formatter.hpp>
#include <CLI/Validators.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "atomic_file.h"
#include "midi/midi_file.h"
#include "note_list.h"
#include "number_arguments.h"
#include "option_values.h"
#include "performance.h"
#include "preset_arguments.h"
#include "preset_search.h"
#include "presets/parameters.h"
#include "progress_bar.h"
#include "standard_output.h"
#include "usage_error.h"
#include "util/format_number.h"
#include "version.h"

namespace hamiltone::cli {
namespace {

struct RenderArguments {
  std::vector<std::string> presets, sets;
  std::string midi, notes, out, format = "pcm24";
  std::string sampleRate = "48000", tail = "3", voices, block = "256", threads;
  bool quiet = false, listParams = false;
};

constexpr double kMaxRenderSeconds = 24.0 * 3600.0;
constexpr double kMaxWavBytes = 4294967295.0 - 1024.0;  // RIFF's 32-bit sizes, less the header

SampleFormat sampleFormat(const std::string& name) {
  if (name == "pcm16") return SampleFormat::pcm16;
  if (name == "float32") return SampleFormat::float32;
  return SampleFormat::pcm24;
}

int run(const RenderArguments& a) {
  if (a.listParams) {
    std::fputs(parameterTable().c_str(), stdout);
    return 0;
  }
  if (a.midi.empty() == a.notes.empty())
    throw UsageError("give exactly one of --midi FILE or --notes LIST");
  if (a.out.empty()) throw UsageError("-o FILE: the sound file to write is required");
  const std::vector<std::string> presets =
      a.presets.empty() ? std::vector<std::string>{HAMILTONE_DEFAULT_PRESET} : a.presets;
  std::vector<InputFile> inputs{{"--midi", a.midi}};
  for (const std::string& preset : presets)
    inputs.push_back({a.presets.empty() ? "--preset (the default)" : "--preset",
                      resolvePreset(preset).string()});
  refuseInputAsOutput("-o", a.out, inputs);
  const FileType type = fileTypeOf(a.out, "-o");
  if (type == FileType::flac && a.format == "float32")
    throw UsageError(
        "--format float32: FLAC holds integer samples; use pcm16 or pcm24, or -o "
        "a .wav file");
  const double rate =
      static_cast<double>(parseInteger("--sample-rate", a.sampleRate, 8000, 384000));
  if (type == FileType::ogg && rate > kOggMaxRate)
    throw UsageError("--sample-rate " + a.sampleRate + ": Ogg Vorbis holds rates up to " +
                     std::to_string(kOggMaxRate) + " Hz; use a lower rate, or -o a .wav or .flac " +
                     "file");
  const double tail = parseReal("--tail", a.tail, Range::nonNegative, "seconds");
  if (tail > 600.0) throw UsageError("--tail = " + a.tail + ": at most 600 seconds");
  const int block = static_cast<int>(parseInteger("--block", a.block, 1, 8192));
  const int voices =
      a.voices.empty() ? 0 : static_cast<int>(parseInteger("--voices", a.voices, 1, 128));
  const int threads =
      a.threads.empty()
          ? 0
          : static_cast<int>(parseInteger("--threads", a.threads, 1, Synth::kMaxThreads));

  // Everything is read and checked before the output file is created.
  // Checked at the render's rate where it is above the usual 48 kHz (a grid fine enough there is
  // not refused for 48 kHz's); below it, at 48 kHz, as keys the score does not play may not exist
  // at a low rate (C8 above 8 kHz's Nyquist frequency): Synth::prepare refuses the played ones.
  std::vector<Instrument> instruments = loadPresets(presets, a.sets, std::max(rate, kCheckRate));
  std::vector<TimedMessage> messages;
  double end = 0.0;
  if (!a.midi.empty()) {
    try {
      MidiFile file = readMidiFile(a.midi);
      messages = std::move(file.messages);
      end = file.lengthSeconds;
    } catch (const MidiFileError& e) {
      throw UsageError(std::string("--midi: ") + e.what());
    }
  } else {
    NoteList list = parseNoteList(a.notes);
    messages = std::move(list.messages);
    end = list.endSeconds;
  }
  if (!(end + tail <= kMaxRenderSeconds))
    throw UsageError((a.midi.empty() ? "--notes" : "--midi " + a.midi) + ": lasts " +
                     formatNumber(end) + " s: at most 24 h can be rendered");
  const double bytesPerSample = a.format == "pcm16" ? 2.0 : a.format == "pcm24" ? 3.0 : 4.0;
  if (type == FileType::wav && (end + tail) * rate * 2.0 * bytesPerSample > kMaxWavBytes)
    throw UsageError("the render would be " + formatNumber(end + tail) + " s at " + a.sampleRate +
                     " Hz in " + a.format +
                     ": more than the 4 GiB a WAV file can hold; use a lower rate or pcm16");
  std::vector<bool> notes(128, false);
  for (const TimedMessage& m : messages)
    if (m.message.kind() == midi::noteOn) notes[m.message.data1 & 0x7F] = true;
  const std::string outside = unplayedNotes(messages, instruments);
  if (!outside.empty())  // a warning, printed under --quiet too
    std::fprintf(stderr,
                 "hamiltone-render: warning: the preset in force does not play MIDI note(s)%s; "
                 "they are silent\n",
                 outside.c_str());
  const std::string unloaded = unloadedPrograms(messages, instruments.size());
  if (!unloaded.empty())
    std::fprintf(stderr, "hamiltone-render: warning: %s\n",
                 ignoredProgramText(unloaded, instruments.size()).c_str());

  Synth synth;
  try {
    synth.prepare(
        std::move(instruments),
        {.sampleRate = rate, .maxBlock = block, .notes = std::move(notes), .threads = threads});
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("preset does not build at this sample rate: ") + e.what());
  }
  synth.setPolyphony(voices);

  WavWriter out(a.out, "-o", static_cast<int>(rate), 2, sampleFormat(a.format), type);
  const double seconds = end + tail;
  ProgressBar bar(seconds, progressStyle(a.quiet));
  const RenderStats stats = renderPerformance(synth, messages, seconds, block, rate, out,
                                              [&](double done) { bar.update(done); });
  bar.finish();
  // An output the program knows is wrong is not written: the temporary goes with `out`.
  if (stats.guardEvents > 0 || stats.nonFinite > 0)
    throw UsageError(instabilityReport(synth, stats));
  out.commit();
  if (!a.quiet) {
    std::fprintf(stderr, "hamiltone-render: %s: %s\n", a.out.c_str(),
                 renderSummary(stats.seconds, stats.wallSeconds).c_str());
    std::fprintf(stderr, "hamiltone-render: %s\n",
                 stealSummary(stats.steals, stats.loudestSteal, synth.polyphony()).c_str());
    std::fprintf(stderr, "hamiltone-render: %s\n",
                 limiterSummary(stats.limitedFrames, stats.overFrames, stats.limiterDeepestDb,
                                stats.peakBeforeLimiter, MasterBus::kCeiling, rate)
                     .c_str());
  } else if (outputSilent(stats.limitedFrames, stats.peakBeforeLimiter)) {
    std::fprintf(stderr, "hamiltone-render: warning: %s: the output is silent: every sample is 0\n",
                 a.out.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace hamiltone::cli

namespace {

int runMain(int argc, char** argv) {
  using namespace hamiltone::cli;
  CLI::App app{
      "hamiltone-render: plays a MIDI file or a list of notes on Hamiltone's physical models and "
      "writes a stereo WAV, FLAC or Ogg Vorbis file."};
  RenderArguments a;
  app.set_version_flag("--version", std::string("hamiltone-render ") + versionText());
  app.add_option("--preset", a.presets,
                 "instrument preset: a TOML file, or the name of one in the preset directories "
                 "($XDG_DATA_HOME, $XDG_DATA_DIRS, the install's share/: hamiltone/presets/); "
                 "repeat it to load several, chosen by MIDI program change (0 = the first). "
                 "Default: " HAMILTONE_DEFAULT_PRESET)
      ->type_name("FILE|NAME");
  addSetOption(&app, a.sets);
  app.add_option("--midi", a.midi, "Standard MIDI File (format 0 or 1) to play")->type_name("FILE");
  app.add_option("--notes", a.notes,
                 "notes to play: NOTE[@START][:VELOCITY[:DURATION]], comma-separated, e.g. "
                 "\"C3:100:2.0, E3@0.5:90:1.5\" (C4 = MIDI 60; START 0, VELOCITY 100 and "
                 "DURATION 1 s by default)")
      ->type_name("LIST");
  app.add_option("-o,--out", a.out,
                 "sound file to write, its format chosen by the extension: .wav, .flac or .ogg "
                 "(Ogg Vorbis); replaced whole, or untouched on error; not an input file")
      ->type_name("FILE");
  addNumberOption(&app, "--sample-rate", a.sampleRate, "HZ", "sample rate, 8000 … 384000");
  app.add_option("--format", a.format, "sample format of a WAV or FLAC file (FLAC: pcm16, pcm24)")
      ->check(CLI::IsMember({"pcm16", "pcm24", "float32"}))
      ->capture_default_str();
  addNumberOption(&app, "--tail", a.tail, "SECONDS", "rendered after the last event, 0 … 600");
  addNumberOption(&app, "--voices", a.voices, "N", "polyphony, 1 … 128 (default: the preset's)");
  addNumberOption(&app, "--block", a.block, "FRAMES", "processing block, 1 … 8192");
  addNumberOption(&app, "--threads", a.threads, "N",
                  "threads rendering the keys, 1 … 256 (default: one per core); the file is the "
                  "same, bit for bit, whatever N");
  app.add_flag("--quiet", a.quiet, "no progress bar and no summary; warnings are still printed");
  app.add_flag("--list-params", a.listParams,
               "print every preset parameter (name, type, unit, range, default) and exit");
  app.footer(
      "Exit codes: 0 done, 1 an I/O error (no file is left), 2 bad input (arguments, preset or "
      "MIDI file, or a preset found unstable for the notes played; no file is written), 128+N "
      "ended by signal N (no file left; a signal ignored when it starts, as under nohup, stays "
      "ignored).");

  try {
    refuseOptionsAsValues(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "hamiltone-render: %s (see hamiltone-render --help)\n", e.what());
    return kExitUsage;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "hamiltone-render: %s (see hamiltone-render --help)\n", e.what());
    return kExitUsage;
  }
  try {
    return run(a);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "hamiltone-render: %s\n", e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hamiltone-render: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  return hamiltone::cli::checkedStandardOutput("hamiltone-render", runMain(argc, argv));
}
