// hamiltone-play: plays presets live from a MIDI keyboard (or a virtual MIDI port), a MIDI file or
// a --notes list through the sound card or a JACK server, optionally recording exactly what it
// plays.
#include <unistd.h>

#include <CLI/App.hpp>
#include <CLI/Config.hpp>
#include <CLI/Formatter.hpp>
#include <CLI/Validators.hpp>
#include <algorithm>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "atomic_file.h"
#include "audio_output.h"
#include "limit_report.h"
#include "midi/midi_file.h"
#include "midi_input.h"
#include "note_list.h"
#include "number_arguments.h"
#include "option_values.h"
#include "player.h"
#include "preset_arguments.h"
#include "recorder.h"
#include "standard_output.h"
#include "stop_signals.h"
#include "usage_error.h"
#include "version.h"

namespace hamiltone::app {
namespace {

struct PlayArguments {
  std::vector<std::string> presets, sets;
  std::string api = "jack", device, sampleRate = "48000", buffer = "128", midiPort, virtualMidi;
  std::string record, voices, threads, midi, notes, cpuLimit = "80";
  bool listDevices = false, quiet = false, keepListening = false;
  bool midiGiven = false, notesGiven = false;  // even empty: "" is not the same as no option
};

// What --midi FILE or --notes LIST plays, read and checked before any device is opened.
struct Score {
  std::vector<TimedMessage> messages;
  std::string what;  // "--midi FILE", "--notes"; "" with no score
};

Score readScore(const PlayArguments& a) {
  if (a.midiGiven && a.notesGiven)
    throw cli::UsageError("give at most one of --midi FILE and --notes LIST");
  Score score;
  if (a.midiGiven) {
    if (a.midi.empty())
      throw cli::UsageError("--midi: the file name is empty; give a Standard MIDI File");
    try {
      score.messages = readMidiFile(a.midi).messages;
    } catch (const MidiFileError& e) {  // "<file>: byte N: what is wrong", or "<file>: why"
      throw cli::UsageError(std::string("--midi: ") + e.what());
    }
    score.what = "--midi " + a.midi;
  } else if (a.notesGiven) {
    score.messages = cli::parseNoteList(a.notes).messages;
    score.what = "--notes";
  }
  return score;
}

// The rate to play at: --sample-rate's, unless the device or server runs at another, which is then
// said in one line. Outside the engine's rates: AudioError.
unsigned playingRate(AudioOutput& audio, int output, unsigned requested) {
  const unsigned rate = chooseSampleRate(requested, audio.device(output));
  const std::string server = audio.api() == "jack" ? "the JACK server" : "the audio device";
  if (rate < 8000 || rate > 384000)
    throw AudioError(server + " runs at " + std::to_string(rate) +
                     " Hz; Hamiltone plays at 8000 … 384000 Hz");
  if (rate != requested)
    std::fprintf(stderr, "hamiltone-play: %s runs at %u Hz: playing at %u Hz, not %u\n",
                 server.c_str(), rate, rate, requested);
  return rate;
}

// A score that sounds nothing, in part or at all, is said (as hamiltone-render says it): notes no
// preset plays, or a MIDI file with no note in it.
void warnSilentScore(const Score& score, const std::vector<Instrument>& instruments) {
  if (score.what.empty()) return;
  const bool anyNote =
      std::any_of(score.messages.begin(), score.messages.end(), [](const TimedMessage& m) {
        return m.message.kind() == midi::noteOn && m.message.data2 > 0;
      });
  const std::string outside = cli::unplayedNotes(score.messages, instruments);
  if (!anyNote)
    std::fprintf(stderr, "hamiltone-play: warning: %s has no note to play\n", score.what.c_str());
  else if (!outside.empty())
    std::fprintf(stderr,
                 "hamiltone-play: warning: the preset in force does not play MIDI note(s)%s; "
                 "they are silent\n",
                 outside.c_str());
}

// No MIDI input port was asked for: what there is, and how to choose one.
void warnNoMidiInput(MidiInput& midi) {
  const std::vector<std::string> ports = midi.ports();
  std::fprintf(stderr,
               "hamiltone-play: warning: no MIDI input is connected, so no key will sound; %s; "
               "choose one with --midi-port N, or make one with --virtual-midi NAME and connect "
               "a keyboard to it (or play --midi FILE / --notes LIST)\n",
               ports.empty() ? "there are no MIDI input ports"
                             : ("MIDI input ports: " + portList(ports)).c_str());
}

constexpr int kExitUsage = cli::kExitUsage;
constexpr int kExitAudioLost = 3;  // the audio server or device went away while playing

std::string describe(std::uint32_t m) {
  if (m == 0) return "-";
  const int status = static_cast<int>(m >> 16), d1 = (m >> 8) & 0x7F, d2 = m & 0x7F;
  char text[48];
  switch (status & 0xF0) {
    case 0x90:
      std::snprintf(text, sizeof text, "on %d/%d", d1, d2);
      break;
    case 0x80:
      std::snprintf(text, sizeof text, "off %d", d1);
      break;
    case 0xB0:
      std::snprintf(text, sizeof text, "cc%d=%d", d1, d2);
      break;
    case 0xC0:
      std::snprintf(text, sizeof text, "program %d", d1);
      break;
    case 0xE0:
      std::snprintf(text, sizeof text, "bend %d", (d2 << 7 | d1) - 8192);
      break;
    default:
      std::snprintf(text, sizeof text, "%02X %d %d", status, d1, d2);
  }
  return text;
}

// The workers take the real-time policy and priority the audio API gave its callback thread (JACK
// with --realtime, ALSA's SCHED_RR): that thread spins until the keys the workers took are done,
// so a worker of lower priority, kept off its core by other programs, would make it late.
// Returns the priority it could not give them, or 0.
int followCallbackScheduling(Synth& synth, pthread_t callback) {
  int policy = SCHED_OTHER;
  sched_param param{};
  if (pthread_getschedparam(callback, &policy, &param) != 0 ||
      (policy != SCHED_FIFO && policy != SCHED_RR))
    return 0;
  return synth.scheduleWorkers(policy, param.sched_priority) ? 0 : param.sched_priority;
}

int listDevices(const std::string& api) {
  std::printf("audio APIs in this build:");
  for (const std::string& a : AudioOutput::compiledApis()) std::printf(" %s", a.c_str());
  std::printf("\n");
  AudioOutput audio(api);
  std::printf("%s output devices:\n", api.c_str());
  for (const AudioDevice& d : audio.devices())
    std::printf("  %d: %s (%d channels)%s\n", d.id, d.name.c_str(), d.outputChannels,
                d.isDefault ? " default" : "");
  MidiInput midi(api);
  std::printf("%s MIDI input ports:\n", api == "pulse" ? "alsa" : api.c_str());
  const std::vector<std::string> ports = midi.ports();
  for (size_t i = 0; i < ports.size(); ++i) std::printf("  %zu: %s\n", i, ports[i].c_str());
  return 0;
}

int play(const PlayArguments& a) {
  if (a.listDevices) return listDevices(a.api);
  if (!a.midiPort.empty() && !a.virtualMidi.empty())
    throw cli::UsageError("give at most one of --midi-port N and --virtual-midi NAME");
  const auto requestedRate =
      static_cast<unsigned>(cli::parseInteger("--sample-rate", a.sampleRate, 8000, 384000));
  unsigned buffer = static_cast<unsigned>(cli::parseInteger("--buffer", a.buffer, 16, 8192));
  const int device =
      a.device.empty() ? -1 : static_cast<int>(cli::parseInteger("--device", a.device, 0));
  const int voices =
      a.voices.empty() ? 0 : static_cast<int>(cli::parseInteger("--voices", a.voices, 1, 128));
  const int threads =
      a.threads.empty()
          ? 0
          : static_cast<int>(cli::parseInteger("--threads", a.threads, 1, Synth::kMaxThreads));
  const double cpuLimit = cli::parseReal("--cpu-limit", a.cpuLimit, cli::Range::positive, "%");
  if (cpuLimit > 100.0) throw cli::UsageError("--cpu-limit = " + a.cpuLimit + ": at most 100 (%)");
  const Score score = readScore(a);
  if (a.keepListening && score.what.empty())
    throw cli::UsageError("--keep-listening goes with --midi FILE or --notes LIST");

  std::vector<cli::InputFile> inputs;
  for (const std::string& file : a.presets) inputs.push_back({"--preset", file});
  if (a.presets.empty()) inputs.push_back({"--preset (the default)", HAMILTONE_DEFAULT_PRESET});
  if (!a.midi.empty()) inputs.push_back({"--midi", a.midi});
  cli::refuseInputAsOutput("--record", a.record, inputs);
  // The file's type by its extension, as hamiltone-render's -o: checked before anything is opened.
  const cli::FileType recordType =
      a.record.empty() ? cli::FileType::wav : cli::fileTypeOf(a.record, "--record");

  // Every signal that would end the program stops it instead, completing the recording: they are
  // taken by this thread alone (sigtimedwait below), and every thread started from here on —
  // audio, MIDI, the recorder — inherits the mask. A signal inherited as ignored (nohup's
  // SIGHUP) is left out: blocked, Linux would queue it for sigtimedwait rather than drop it.
  sigset_t stopSignals;
  sigemptyset(&stopSignals);
  for (const int s : cli::AtomicFile::endingSignals()) {
    struct sigaction current {};
    if (::sigaction(s, nullptr, &current) == 0 && current.sa_handler != SIG_IGN)
      sigaddset(&stopSignals, s);
  }
  pthread_sigmask(SIG_BLOCK, &stopSignals, nullptr);
  std::unique_ptr<Recorder> recorder;  // outlives the stop signals' thread, which may finish it
  StopSignals stops(stopSignals);

  // Presets load and their voices are built here, off the audio thread; program change then only
  // switches between instruments that are ready.
  std::vector<Instrument> instruments = cli::loadPresets(
      a.presets.empty() ? std::vector<std::string>{HAMILTONE_DEFAULT_PRESET} : a.presets, a.sets);
  warnSilentScore(score, instruments);

  AudioOutput audio(a.api);  // AudioError: exit 2 with what exists
  const int output = audio.resolve(device);
  const unsigned rate = playingRate(audio, output, requestedRate);
  MidiInput midi(a.api);
  Synth synth;
  try {
    synth.prepare(std::move(instruments), {.sampleRate = static_cast<double>(rate),
                                           .maxBlock = 8192,
                                           .notes = {},
                                           .threads = threads});
  } catch (const std::invalid_argument& e) {
    throw cli::UsageError(std::string("preset does not build at this sample rate: ") + e.what());
  }
  synth.setPolyphony(voices);
  if (!a.record.empty()) {
    if (recordType == cli::FileType::ogg && rate > cli::kOggMaxRate)
      throw cli::UsageError("--record = " + a.record + ": Ogg Vorbis holds at most " +
                            std::to_string(cli::kOggMaxRate) + " Hz, and the stream runs at " +
                            std::to_string(rate) + " Hz; record to a .wav or .flac file");
    recorder = std::make_unique<Recorder>(a.record, static_cast<int>(rate), recordType);
    stops.setRecorder(recorder.get());  // from its temporary on: a forced end removes it
  }
  Player player(synth, midi.queue(), recorder ? &recorder->ring() : nullptr, rate, 8192,
                cpuLimit / 100.0);
  if (!score.what.empty()) player.setScore(score.messages, !a.keepListening);

  audio.open(output, rate, buffer, [&player](float* out, int frames, bool) {
    player.render(out, frames, steadyNanoseconds());
  });
  if (audio.streamRate() != rate)
    throw AudioError("the audio stream opened at " + std::to_string(audio.streamRate()) +
                     " Hz, not the " + std::to_string(rate) + " Hz asked for");
  if (!a.virtualMidi.empty())
    midi.openVirtualPort(a.virtualMidi);
  else if (!a.midiPort.empty())
    midi.openPort(static_cast<int>(cli::parseInteger("--midi-port", a.midiPort, 0)));
  else if (score.what.empty() || a.keepListening)
    warnNoMidiInput(midi);
  if (recorder) recorder->start();
  audio.start();

  const bool status = !a.quiet && ::isatty(2);
  if (!a.quiet)
    std::fprintf(stderr,
                 "hamiltone-play: %s, %u Hz, %u frames (%.1f ms), %d thread%s%s%s; Ctrl-C stops\n",
                 a.api.c_str(), rate, buffer, 1000.0 * buffer / rate, synth.threads(),
                 synth.threads() == 1 ? "" : "s", score.what.empty() ? "" : "; playing ",
                 score.what.c_str());
  LimitReport limits({.budget = cpuLimit / 100.0,
                      .frames = static_cast<int>(buffer),
                      .sampleRate = static_cast<double>(rate),
                      .threads = synth.threads(),
                      .cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency())),
                      .polyphony = synth.polyphony(),
                      .jack = a.api == "jack"});
  const timespec started = [] {
    timespec t{};
    ::clock_gettime(CLOCK_MONOTONIC, &t);
    return t;
  }();
  timespec wait{0, 250'000'000};
  int signal = -1, polls = 0;
  std::uint64_t ignoredShown[2] = {};  // the ignored programs said so far
  bool recordingFailureShown = false, lost = false, scheduled = false, finished = false,
       portGone = false;
  while (signal < 0) {
    signal = stops.wait(wait);
    if (signal >= 0) break;
    if (!scheduled && player.callbackThread()) {
      scheduled = true;
      const int refused = followCallbackScheduling(synth, *player.callbackThread());
      if (refused > 0 && !a.quiet)
        std::fprintf(stderr,
                     "%shamiltone-play: warning: the worker threads could not take the audio "
                     "thread's real-time priority %d; under load they may make it late\n",
                     status ? "\n" : "", refused);
    }
    // A server that went away (JACK shuts its clients down) leaves nothing to play on.
    if (audio.lost()) {
      lost = true;
      break;
    }
    const Player::Status s = player.status();
    // The score played and its last key silent: done, unless asked to listen on.
    if (s.finished && !a.keepListening) {
      finished = true;
      break;
    }
    timespec now{};
    ::clock_gettime(CLOCK_MONOTONIC, &now);
    const std::string limitLine = limits.update(
        s, double(now.tv_sec - started.tv_sec) + 1e-9 * double(now.tv_nsec - started.tv_nsec));
    if (!limitLine.empty())
      std::fprintf(stderr, "%shamiltone-play: %s\n", status ? "\n" : "", limitLine.c_str());
    // Program changes past the last preset (live or in the score): each program said once.
    std::vector<bool> unsaid(128, false);
    for (int p = 0; p < 128; ++p) {
      const std::uint64_t bit = std::uint64_t{1} << (p % 64);
      unsaid[p] = (s.ignoredPrograms[p / 64] & bit) && !(ignoredShown[p / 64] & bit);
    }
    for (int w = 0; w < 2; ++w) ignoredShown[w] = s.ignoredPrograms[w];
    if (const std::string programs = cli::numberList(unsaid); !programs.empty())
      std::fprintf(stderr, "%shamiltone-play: warning: %s\n", status ? "\n" : "",
                   cli::ignoredProgramText(programs, synth.instruments().size()).c_str());
    // The keyboard's port, once a second: unplugged, or its program gone; back, or (on JACK)
    // gone and back between two checks, its connection gone with its old port.
    if (++polls % 4 == 0 && !midi.portName().empty()) {
      const bool present = midi.portPresent();
      if (!portGone && !present) {
        portGone = true;
        std::fprintf(stderr,
                     "%shamiltone-play: warning: the MIDI input port \"%s\" is gone, so no MIDI "
                     "input is connected; MIDI input ports now: %s; it is connected again when it "
                     "comes back, or restart with --midi-port N to choose another\n",
                     status ? "\n" : "", midi.portName().c_str(), portList(midi.ports()).c_str());
      } else if (present && (portGone || midi.portReturned())) {
        const char* how = portGone ? "is back: connected" : "went and came back: connected again";
        try {
          midi.reconnect();
          portGone = false;
          std::fprintf(stderr, "%shamiltone-play: the MIDI input port \"%s\" %s\n",
                       status ? "\n" : "", midi.portName().c_str(), how);
        } catch (const MidiError&) {
          portGone = true;  // tried again in a second
        }
      }
    }
    // A failed recording is said at once, on a line of its own; the sound plays on.
    if (recorder && recorder->failed() && !recordingFailureShown) {
      recordingFailureShown = true;
      std::fprintf(stderr,
                   "%shamiltone-play: recording stopped at %.2f s: %s; still playing (the %.2f s "
                   "written are kept at exit)\n",
                   status ? "\n" : "", recorder->failedAtSeconds(), recorder->error().c_str(),
                   recorder->failedAtSeconds());
    }
    if (!status) continue;
    std::fprintf(stderr,
                 "\r  voices %2d/%-3d  cpu %3.0f%% (peak %3.0f%%)  underruns %ld (late %ld)  "
                 "midi %-12s  guard %d%s%s   ",
                 s.voices, s.limit, 100.0 * s.load, 100.0 * s.peakLoad, audio.underruns(), s.late,
                 describe(s.lastMessage).c_str(), s.guardEvents,
                 s.liveTail ? "  live tails" : "            ",
                 recordingFailureShown ? "  REC STOPPED" : "");
    std::fflush(stderr);
  }
  // The MIDI input first, while the graph is otherwise still: on JACK its client is deactivated and
  // then closed (jack_midi_input.h). RtMidi's input, which unregistered its port on an active
  // client, crashed the player here once, in libjack's latency recompute, and lost its recording.
  midi.close();
  audio.stop();
  stops.released();
  const Player::Status s = player.status();
  if (status) std::fprintf(stderr, "\n");
  if (lost)
    std::fprintf(stderr,
                 "hamiltone-play: error: the audio stream is gone: %s; underruns %ld; late "
                 "callbacks %ld; peak cpu %.0f%%; guard events %d\n",
                 audio.lostReason().c_str(), audio.underruns(), s.late, 100.0 * s.peakLoad,
                 s.guardEvents);
  else
    std::fprintf(stderr,
                 "hamiltone-play: %s; underruns %ld; late callbacks %ld; peak cpu "
                 "%.0f%%; guard events %d\n",
                 finished ? ("played " + score.what + " to the end").c_str()
                          : ("stopped by " + signalName(signal)).c_str(),
                 audio.underruns(), s.late, 100.0 * s.peakLoad, s.guardEvents);
  if (s.limitedFrames > 0)
    std::fprintf(stderr,
                 "hamiltone-play: the master's limiter reduced the gain by up to %.1f dB on %ld "
                 "frames: lower the volume (CC7) or the preset's gain_dB\n",
                 s.limiterDeepestDb, s.limitedFrames);
  if (recorder) {
    const double seconds = recorder->finish();
    std::fprintf(stderr, "hamiltone-play: %s%s\n", recorder->failed() ? "error: " : "",
                 recorder->outcome(seconds, s.recordDropped).c_str());
    if (recorder->failed()) return 1;
  }
  if (lost) return kExitAudioLost;
  if (finished) return 0;
  return stopExitCode(signal);
}

}  // namespace
}  // namespace hamiltone::app

namespace {

int runMain(int argc, char** argv) {
  using namespace hamiltone::app;
  namespace cli = hamiltone::cli;
  CLI::App app{"hamiltone-play: plays Hamiltone's physical models live from MIDI."};
  PlayArguments a;
  app.set_version_flag("--version", std::string("hamiltone-play ") + cli::versionText());
  app.add_option("--preset", a.presets,
                 "instrument preset (TOML); repeat it to load several, chosen by MIDI program "
                 "change (0 = the first). Default: " HAMILTONE_DEFAULT_PRESET)
      ->type_name("FILE");
  cli::addSetOption(&app, a.sets);
  app.add_option("--api", a.api, "audio (and MIDI) API")
      ->check(CLI::IsMember({"jack", "alsa", "pulse"}))
      ->capture_default_str();
  cli::addNumberOption(&app, "--device", a.device, "N", "output device (see --list-devices)");
  cli::addNumberOption(&app, "--sample-rate", a.sampleRate, "HZ", "sample rate");
  cli::addNumberOption(&app, "--buffer", a.buffer, "FRAMES", "buffer size asked of the device");
  cli::addNumberOption(&app, "--midi-port", a.midiPort, "N",
                       "MIDI input port (see --list-devices)");
  app.add_option("--virtual-midi", a.virtualMidi, "create a MIDI input port with this name")
      ->type_name("NAME")
      ->check([](const std::string& name) {
        return name.empty() ? std::string("is empty: expected a port name") : std::string();
      });
  app.add_option("--midi", a.midi,
                 "also play this Standard MIDI File (format 0 or 1) live, from the start of the "
                 "stream; the player exits when it has played and its last note died away")
      ->type_name("FILE");
  app.add_option("--notes", a.notes,
                 "also play these notes live (a test chord), as hamiltone-render --notes: "
                 "NOTE[@START][:VELOCITY[:DURATION]], comma-separated, e.g. \"C4, E4, G4\" "
                 "(C4 = MIDI 60; START 0, VELOCITY 100 and DURATION 1 s by default); the player "
                 "exits when they have died away")
      ->type_name("LIST");
  app.add_flag("--keep-listening", a.keepListening,
               "after --midi or --notes, play on from MIDI input until stopped");
  app.add_option("--record", a.record,
                 "also write what is played to this file, its type chosen by the extension: "
                 ".wav or .flac (24-bit), .ogg (Ogg Vorbis)")
      ->type_name("FILE")
      ->check([](const std::string& path) {
        return path.empty() ? std::string("is empty: expected a file path") : std::string();
      });
  cli::addNumberOption(&app, "--voices", a.voices, "N",
                       "polyphony, 1 … 128 (default: the preset's)");
  cli::addNumberOption(&app, "--threads", a.threads, "N",
                       "threads rendering the keys, the audio callback's included, 1 … 256 "
                       "(default: one per core); the sound is the same whatever N");
  cli::addNumberOption(&app, "--cpu-limit", a.cpuLimit, "PERCENT",
                       "share of the buffer period the audio callback may take before the voice "
                       "limit drops (from three quarters of it the strings' tails go linear "
                       "sooner), above 0, at most 100");
  app.add_flag("--list-devices", a.listDevices, "list the APIs, output devices and MIDI ports");
  app.add_flag("--quiet", a.quiet, "no status line");
  app.footer(
      "Signals: SIGINT, SIGTERM and SIGHUP stop it normally; SIGQUIT (Ctrl-\\), SIGUSR1, SIGPIPE, "
      "SIGALRM and the other signals sent to end it stop it too, completing the recording, and "
      "exit 128+N; "
      "a signal ignored when it starts (nohup) stays ignored. "
      "Exit codes: 0 stopped by SIGINT/SIGTERM/SIGHUP, or --midi/--notes played to the end (the "
      "recording is complete), 1 an I/O error "
      "(a recording that failed, e.g. on a full disk, keeps what was written before the error), "
      "2 bad input (arguments, preset, MIDI file) or no usable audio API/device, 3 the audio "
      "server or device went away while "
      "playing (the recording is complete up to then).");
  try {
    hamiltone::cli::refuseOptionsAsValues(app, argc, argv);
    app.parse(argc, argv);
    a.midiGiven = app.count("--midi") > 0;
    a.notesGiven = app.count("--notes") > 0;
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "hamiltone-play: %s (see hamiltone-play --help)\n", e.what());
    return kExitUsage;
  } catch (const hamiltone::cli::UsageError& e) {
    std::fprintf(stderr, "hamiltone-play: %s (see hamiltone-play --help)\n", e.what());
    return kExitUsage;
  }
  try {
    return play(a);
  } catch (const hamiltone::cli::UsageError& e) {
    std::fprintf(stderr, "hamiltone-play: %s\n", e.what());
  } catch (const AudioError& e) {
    std::fprintf(stderr, "hamiltone-play: %s\n", e.what());
  } catch (const MidiError& e) {
    std::fprintf(stderr, "hamiltone-play: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hamiltone-play: error: %s\n", e.what());
    return 1;
  }
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  return hamiltone::cli::checkedStandardOutput("hamiltone-play", runMain(argc, argv));
}
