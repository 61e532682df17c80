// The synthesizer: the loaded instruments, a voice for every key of each (built in prepare(),
// never on the audio path), MIDI semantics, voice allocation under a polyphony limit, and the
// master section. process() is real-time safe: no allocation, lock or I/O; the keys it shares with
// the worker threads (SynthSetup::threads) are handed over without a lock (synth/worker_pool.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "instruments/piano_body.h"
#include "midi/midi_message.h"
#include "synth/instrument.h"
#include "synth/key_voice.h"
#include "synth/master_bus.h"
#include "synth/worker_pool.h"

namespace hamiltone {

// A message at a sample offset inside the block being processed.
struct SynthEvent {
  int offset = 0;
  MidiMessage message;
};

struct SynthSetup {
  double sampleRate = 48000.0;
  int maxBlock = 1024;  // process() takes any number of frames; it works in pieces of this size
  // Which MIDI notes get voices; empty: every note of each instrument's range. An offline render
  // that knows its notes saves the preparation of the others (plates are slow to prepare).
  std::vector<bool> notes;
  // Threads that render the keys, the caller's included: 0, one per core; 1, the caller alone.
  // The output is bit-identical whatever the count (each key renders into its own buffer; the
  // buffers are summed in a fixed order).
  int threads = 0;
  // Voices free themselves once silent, held or not (QuietDetector); false keeps them until they
  // are stolen or silenced, for tests to compare against.
  bool freeQuietVoices = true;
};

// MIDI, omni (every channel plays the current instrument):
//   note on/off (velocity 0 is a note-off; a note-off's velocity sets how fast the damper acts,
//   releaseScale()); a note-on for a sounding key re-strikes that key's
//   voice (its strings keep vibrating, as on a piano); CC64 sustain, continuous (half-pedalling,
//   damperContact()): the dampers of the keys released while it is down touch their strings with
//   the pedal's contact, from fully on (0…20, as with no pedal) to fully lifted (100…127), and
//   follow it until it is fully up; CC66 sostenuto, 64…127 down: the keys held as it goes down
//   keep their dampers off the strings after their release until it lifts, keys struck later do
//   not; CC67 una corda, 64…127 down: keys struck meanwhile strike two strings of three
//   (UnisonStrings::noteOn); CC7 volume, gain
//   (value/127)², smoothed over 10 ms; CC120 all sound off: every voice fades out in 5 ms;
//   CC121 reset controllers: bend centred, pedals up; CC123 all notes off: as a note-off for every
//   held key (the pedal still sustains them); pitch bend ±bend_range_semitones of the instrument
//   (strings retension, plates do not bend); program change n selects instrument n (ignored
//   beyond the last), sounding notes ring on in the old one.
class Synth {
 public:
  static constexpr int kMaxThreads = 256;

  // May allocate and start the worker threads; throws std::invalid_argument naming the
  // instrument, note and patch field (or the thread count).
  void prepare(std::vector<Instrument> instruments, const SynthSetup& setup);

  // Writes left.size() frames (right must be as long). `events` sorted by offset, each offset in
  // [0, left.size()); an event out of order is applied at once, one past the block after it.
  void process(std::span<float> left, std::span<float> right,
               std::span<const SynthEvent> events) noexcept;
  void handle(const MidiMessage& message) noexcept;  // now, between two samples

  // The limit on sounding keys; 0 restores the instrument's own polyphony. Keys beyond a lowered
  // limit fade out at once, those furthest below their own peak first (as stealOne()).
  void setPolyphony(int voices) noexcept;
  // How long the dampers take, as a multiple of each key's damper_t60_s (1: the preset's), clamped
  // to 0.1 … 10: a performance control, like the pedal, for the keys released from now on.
  void setDamperScale(double scale) noexcept;
  // How much of its loss a released key's damper puts on the strings at CC64 `value`: 1 (fully on)
  // up to 20, 0 (fully lifted) from 100, linear in between. A real damper pedal has free play at
  // the top (the lever has not yet reached the damper tray; a sensor also reads a few counts at
  // rest) and lifts the dampers clear of the strings before it bottoms out; between the two the
  // felt's pressure on the string, and with it the loss it adds, grows with the way it is pressed
  // in. So 0 and 127 are today's up and down to the bit, and 64 is a half pedal (contact 0.45).
  static double damperContact(int value) noexcept;
  // Every string key's live tail (StringVoice::setLiveTail): on, a decaying string goes linear at
  // a tension modulation of 1e-3 rather than its preset's (5e-5 by default), and steps its
  // modes at a tenth to a fifth of the cost, its pitch off by at most 0.87 cents; the modes under
  // −80 dB of its energy are dropped, not −100 dB (kLiveModalFloor). For a live player
  // under load, before it drops keys (app::Player); renders never take it, so their output stays
  // the preset's. Off: the strings not yet linear go on to the preset's threshold, the linear ones
  // stay linear.
  void setLiveTail(bool on) noexcept;
  bool liveTail() const { return liveTail_; }
  // The instrument playing now has strings whose tail the live tail moves (not a plate, nor a
  // preset with linear_below 0, nor the transverse grid).
  bool takesLiveTail() const { return takesLiveTail_[program_] != 0; }
  // How a note-off's release velocity scales its damper's T60: 2^((64 − v)/63) — a key let go
  // fast (127) damps in half the time, a slow one (1) in twice, 64 as the preset says; 0 (no
  // velocity given, or a note-on at velocity 0) is 1.
  static double releaseScale(int velocity) noexcept;
  int polyphony() const;
  int activeVoices() const;
  // The sounding strings that step their linear tail in their modes (StringVoice::inModes()).
  int stringsInModes() const;
  // No key sounds, fades out or waits to be struck: what comes out now is the master bus's
  // DC-blocker tail at most. (activeVoices() does not count a key fading out.)
  bool silent() const;
  int program() const { return program_; }
  // The CC7 volume at its last value at once, not smoothed from where it was: for a synthesizer
  // that takes over the controllers of another (the plugin's swap), whose volume was never full.
  void settleVolume() noexcept { master_.settleVolume(); }
  // The programs past the last instrument that program changes asked for since prepare(), a bit
  // each (program p: bit p % 64 of word p / 64): ignored, so that a front end can say so.
  std::uint64_t ignoredPrograms(int word) const { return ignoredPrograms_[word]; }
  int guardEvents() const;
  long nonFiniteSamples() const { return master_.nonFinite(); }
  // The master's limiter and its meters since prepare(): how often and how deep it acted.
  const PeakLimiter& limiter() const { return master_.limiter(); }
  int threads() const { return pool_ ? pool_->threads() : 1; }
  // The worker threads take this scheduling policy and priority (see WorkerPool::schedule).
  bool scheduleWorkers(int policy, int priority) noexcept {
    return pool_ && pool_->schedule(policy, priority);
  }
  // Keys stolen since prepare(), and the highest level under its own peak any of them had when
  // taken (KeyVoice::level: 1e-3 is −60 dB) — how much sound the polyphony limit has cut.
  long steals() const { return steals_; }
  double loudestSteal() const { return loudestSteal_; }
  const std::vector<Instrument>& instruments() const { return instruments_; }
  // The key's voice, or nullptr when that note has none.
  const KeyVoice* voice(int program, int note) const;

 private:
  void render(std::span<float> left, std::span<float> right) noexcept;
  void noteOn(int note, int velocity) noexcept;
  void noteOff(int note, int velocity = 0) noexcept;
  void setSustain(int value) noexcept;    // CC64
  void setSostenuto(bool down) noexcept;  // CC66
  void setBend(double fraction) noexcept;
  void allSoundOff() noexcept;
  KeyVoice* keyVoice(int program, int note);
  bool stealOne() noexcept;

  struct BusyKey {
    KeyVoice* voice;
    double gain;                // its instrument's
    const float *left, *right;  // its outputs (read while it renders its next part)
  };
  // An instrument's body (BodyPatch), stepped sample by sample after its keys (synth_render.cpp):
  // the keys' bridges drive it, every key not sounding as a voice rings in it in sympathy (its
  // damper lifted while the key is held, caught by the sostenuto or the pedal is down).
  struct Body {
    PianoBody body;
    std::vector<double> forces;  // per key, this sample, N
    std::vector<int> drivers;    // the keys rendered this piece (driverCount), in order …
    int driverCount = 0;
    std::vector<const float*> driving;  // … and their board forces …
    std::vector<int> slots;             // … and their places in busy_
    bool idle = false;                  // resting with no driver: nothing to step this piece
    // The keys whose voices ended in this piece (rejoinCount) and the sample their strings come
    // back to the board.
    std::vector<std::pair<long, int>> rejoins;
    int rejoinCount = 0;
    std::vector<long> struck;           // per key, the strike (KeyVoice::order) it last saw …
    std::vector<long> excludedAt;       // … and `clock` then: left out of the coupling since
    std::vector<double> contact;        // per key, as last told (−1: not yet)
    double gain = 1.0;                  // body.gain times the instrument's
    long clock = 0, lastPush = 0;       // samples since prepare(); the last with a force …
    long lastLoud = 0;                  // … and the last the body was heard over the quiet floor
    int fadeSamples = 1, fadeLeft = 0;  // silenced (CC120): fades like a voice, then rests
    bool resting = true;
  };
  static constexpr long kBodyRestCheck = 4096;  // samples between the body's rest checks
  // A piece: its keys, then each body over it; on the pool, in parts of kPart samples, a body
  // stepping one part while the keys render the next (synth_render.cpp).
  static constexpr size_t kPart = 64;
  void renderAtOnce(int count, std::span<float> left, std::span<float> right) noexcept;
  void renderInParts(int count, std::span<float> left, std::span<float> right) noexcept;
  void mixKeys(int count, size_t from, size_t to, std::span<float> left,
               std::span<float> right) noexcept;
  void beginBody(size_t program, size_t frames) noexcept;
  void stepBody(size_t program, size_t from, size_t to, size_t frames, std::span<float> left,
                std::span<float> right) noexcept;
  static void rest(Body& b) noexcept;
  static constexpr long kNever = -(1L << 40);  // a clock long before any sample

  std::vector<Instrument> instruments_;
  std::vector<std::vector<KeyVoice>> voices_;  // [instrument][note − lowest]
  std::vector<std::vector<bool>> hasVoice_;
  std::vector<double> gains_;  // per instrument, linear
  // The keys a piece renders, in (instrument, note) order; room for every key.
  std::vector<BusyKey> busy_;
  std::unique_ptr<WorkerPool> pool_;  // renders busy_ (a pointer: the pool's threads stay put)
  // In parts: per busy key, the parts it has rendered and the sample its voice ended at (−1: not
  // in this piece); per part, the keys that have rendered it; the parts mixed (keys summed and
  // bodies stepped). On the heap, so that the synthesizer moves.
  std::unique_ptr<std::atomic<int>[]> keyParts_;
  std::unique_ptr<std::atomic<long>[]> keyFreedAt_;
  std::unique_ptr<std::atomic<int>[]> partKeys_;
  std::unique_ptr<std::atomic<int>> mixedParts_;
  bool inParts_ = false;  // the pool has 2 threads or more, and no more than the cores
  std::vector<std::unique_ptr<Body>> bodies_;  // per instrument; null without a body
  MasterBus master_;
  int maxBlock_ = 0;
  int program_ = 0, polyphonyOverride_ = 0;
  std::uint64_t ignoredPrograms_[2] = {};
  int downProgram_[128];  // which instrument's voice a held note struck (−1: none)
  bool sostenuto_ = false, unaCorda_ = false;
  bool liveTail_ = false;
  std::vector<char> takesLiveTail_;  // per instrument (takesLiveTail())
  double contact_ = 1.0;  // of the dampers of the keys released under the pedal (damperContact)
  double bend_ = 0.0;     // −1 … 1 of the range
  double damperScale_ = 1.0;
  long strikes_ = 0;
  long steals_ = 0;
  double loudestSteal_ = 0.0;
};

}  // namespace hamiltone
