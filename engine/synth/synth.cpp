// The synthesizer's event handling (MIDI semantics, voice allocation and stealing) and its block
// loop: events applied at their exact sample, voices summed, then the master section.
#include "synth/synth.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "synth/denormals.h"
#include "synth/instrument_body.h"

namespace hamiltone {

void Synth::prepare(std::vector<Instrument> instruments, const SynthSetup& setup) {
  if (instruments.empty()) throw std::invalid_argument("no instrument to play");
  if (setup.maxBlock < 1 || setup.maxBlock > 65536)
    throw std::invalid_argument("block size " + std::to_string(setup.maxBlock) +
                                ": must be between 1 and 65536 frames");
  if (setup.threads < 0 || setup.threads > kMaxThreads)
    throw std::invalid_argument("threads = " + std::to_string(setup.threads) +
                                ": must be between 0 (one per core) and " +
                                std::to_string(kMaxThreads));
  std::vector<std::vector<KeyVoice>> voices(instruments.size());
  std::vector<std::vector<bool>> hasVoice(instruments.size());
  std::vector<double> gains;
  size_t keys = 0;
  for (size_t p = 0; p < instruments.size(); ++p) {
    const Instrument& instrument = instruments[p];
    if (instrument.polyphony < 1 || instrument.lowestNote > instrument.highestNote)
      throw std::invalid_argument(
          instrument.source + ": polyphony " + std::to_string(instrument.polyphony) +
          " and notes " + std::to_string(instrument.lowestNote) + " … " +
          std::to_string(instrument.highestNote) + ": need at least one voice and one note");
    const int count = instrument.highestNote - instrument.lowestNote + 1;
    voices[p].resize(count);
    hasVoice[p].assign(count, false);
    for (int i = 0; i < count; ++i) {
      const int note = instrument.lowestNote + i;
      if (!setup.notes.empty() &&
          (note >= static_cast<int>(setup.notes.size()) || !setup.notes[note]))
        continue;
      try {
        voices[p][i].prepare(instrument, note, setup.sampleRate, setup.maxBlock,
                             setup.freeQuietVoices);
      } catch (const std::exception& e) {
        throw std::invalid_argument(instrument.source + ": note " + std::to_string(note) + ": " +
                                    e.what());
      }
      hasVoice[p][i] = true;
      ++keys;
    }
    gains.push_back(std::pow(10.0, instrument.gainDb / 20.0));
  }
  std::vector<std::unique_ptr<Body>> bodies(instruments.size());
  for (size_t p = 0; p < instruments.size(); ++p) {
    const Instrument& instrument = instruments[p];
    if (instrument.model != InstrumentModel::string || !instrument.body.enabled) continue;
    auto body = std::make_unique<Body>();
    try {
      prepareBody(body->body, instrument, setup.sampleRate);
    } catch (const std::exception& e) {
      throw std::invalid_argument(instrument.source + ": " + e.what());
    }
    const size_t count = instrument.keys.size();
    body->forces.assign(count, 0.0);
    body->driving.assign(count, nullptr);
    body->rejoins.assign(count, {-1, 0});
    body->drivers.assign(count, 0);
    body->slots.assign(count, 0);
    body->struck.assign(count, 0);
    body->excludedAt.assign(count, kNever);
    body->contact.assign(count, -1.0);
    body->gain = instrument.body.gain * gains[p];
    body->fadeSamples = KeyVoice::fadeSamples(setup.sampleRate);
    bodies[p] = std::move(body);
  }
  MasterBus master;
  master.prepare(setup.sampleRate);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  auto pool = std::make_unique<WorkerPool>(setup.threads > 0 ? setup.threads : cores);
  auto keyParts = std::make_unique<std::atomic<int>[]>(keys);
  auto keyFreedAt = std::make_unique<std::atomic<long>[]>(keys);
  auto partKeys = std::make_unique<std::atomic<int>[]>((setup.maxBlock + kPart - 1) / kPart);
  auto mixedParts = std::make_unique<std::atomic<int>>(0);

  instruments_ = std::move(instruments);
  voices_ = std::move(voices);
  hasVoice_ = std::move(hasVoice);
  gains_ = std::move(gains);
  busy_.assign(keys, {});
  keyParts_ = std::move(keyParts);
  keyFreedAt_ = std::move(keyFreedAt);
  partKeys_ = std::move(partKeys);
  mixedParts_ = std::move(mixedParts);
  // In parts only where each thread has a core: a job waits by spinning, and a thread spinning
  // for one that has no core to run on would hold it back.
  inParts_ = pool->threads() > 1 && pool->threads() <= cores;
  pool_ = std::move(pool);
  bodies_ = std::move(bodies);
  master_ = master;
  maxBlock_ = setup.maxBlock;
  program_ = 0;
  ignoredPrograms_[0] = ignoredPrograms_[1] = 0;
  std::fill(std::begin(downProgram_), std::end(downProgram_), -1);
  contact_ = 1.0;
  sostenuto_ = unaCorda_ = liveTail_ = false;
  takesLiveTail_.assign(instruments_.size(), 0);
  for (size_t p = 0; p < voices_.size(); ++p)
    for (const KeyVoice& v : voices_[p]) takesLiveTail_[p] = takesLiveTail_[p] || v.takesLiveTail();
  bend_ = 0.0;
  strikes_ = steals_ = 0;
  loudestSteal_ = 0.0;
}

KeyVoice* Synth::keyVoice(int program, int note) {
  const Instrument& instrument = instruments_[program];
  if (note < instrument.lowestNote || note > instrument.highestNote) return nullptr;
  const int i = note - instrument.lowestNote;
  return hasVoice_[program][i] ? &voices_[program][i] : nullptr;
}

const KeyVoice* Synth::voice(int program, int note) const {
  if (program < 0 || program >= static_cast<int>(instruments_.size())) return nullptr;
  return const_cast<Synth*>(this)->keyVoice(program, note);
}

void Synth::setPolyphony(int voices) noexcept {
  polyphonyOverride_ = std::max(voices, 0);
  while (activeVoices() > polyphony() && stealOne()) {
  }
}

double Synth::damperContact(int value) noexcept {
  constexpr int kFreePlay = 20, kLifted = 100;
  if (value <= kFreePlay) return 1.0;
  if (value >= kLifted) return 0.0;
  return static_cast<double>(kLifted - value) / (kLifted - kFreePlay);
}

void Synth::setDamperScale(double scale) noexcept {
  damperScale_ = std::isnan(scale) ? 1.0 : std::clamp(scale, 0.1, 10.0);
}

int Synth::polyphony() const {
  return polyphonyOverride_ > 0 ? polyphonyOverride_ : instruments_[program_].polyphony;
}

int Synth::activeVoices() const {
  int count = 0;
  for (const auto& keys : voices_)
    for (const KeyVoice& v : keys) count += (v.sounding() && !v.fading()) || v.pending();
  return count;
}

int Synth::stringsInModes() const {
  int count = 0;
  for (const auto& keys : voices_)
    for (const KeyVoice& v : keys) count += v.stringsInModes();
  return count;
}

bool Synth::silent() const {
  for (const auto& keys : voices_)
    for (const KeyVoice& v : keys)
      if (v.busy()) return false;
  for (const auto& body : bodies_)
    if (body && !body->resting) return false;  // the board and its strings still ring
  return true;
}

int Synth::guardEvents() const {
  int events = 0;
  for (const auto& keys : voices_)
    for (const KeyVoice& v : keys) events += v.guardEvents();
  return events;
}

// The key furthest below its own peak (KeyVoice::level): the furthest into its decay, whether
// a damper or its own loss is taking it there, so the least of what it still had to sound is
// cut; on a tie (keys just struck count as at their peak) a released key (neither held nor
// sustained) first, then the oldest. It fades out over 5 ms. False when no key can be taken (all
// are fading already).
bool Synth::stealOne() noexcept {
  KeyVoice* victim = nullptr;
  auto better = [&](const KeyVoice& v) {
    if (!victim) return true;
    if (v.level() != victim->level()) return v.level() < victim->level();
    const bool free = !v.down && !v.sustained && !v.caught,
               victimFree = !victim->down && !victim->sustained && !victim->caught;
    if (free != victimFree) return free;
    return v.order() < victim->order();
  };
  for (auto& keys : voices_)
    for (KeyVoice& v : keys)
      if (v.sounding() && !v.fading() && !v.pending() && better(v)) victim = &v;
  if (!victim) return false;
  ++steals_;
  loudestSteal_ = std::max(loudestSteal_, victim->level());
  victim->fadeOut();
  return true;
}

void Synth::noteOn(int note, int velocity) noexcept {
  KeyVoice* voice = keyVoice(program_, note);
  if (!voice) return;
  // The key held in another instrument (before a program change) is let go first.
  if (downProgram_[note] >= 0 && downProgram_[note] != program_) noteOff(note);
  const bool counted = (voice->sounding() && !voice->fading()) || voice->pending();
  if (!counted)
    while (activeVoices() >= polyphony() && stealOne()) {
    }
  voice->setBend(bend_ * instruments_[program_].bendRange);
  voice->strike(velocity / 127.0, ++strikes_, unaCorda_);
  voice->down = true;
  voice->sustained = false;
  downProgram_[note] = program_;
}

double Synth::releaseScale(int velocity) noexcept {
  if (velocity <= 0) return 1.0;  // none given (a note-on at velocity 0, or a keyboard's 0)
  return std::exp2((64.0 - std::min(velocity, 127)) / 63.0);
}

void Synth::noteOff(int note, int velocity) noexcept {
  if (downProgram_[note] < 0) return;
  KeyVoice* voice = keyVoice(downProgram_[note], note);
  downProgram_[note] = -1;
  if (!voice || !voice->down) return;
  voice->down = false;
  voice->releaseScale = releaseScale(velocity);
  const double damperScale = damperScale_ * voice->releaseScale;
  if (voice->caught) {  // the sostenuto pedal holds its damper up
    voice->sustained = contact_ < 1.0;
    return;
  }
  if (contact_ < 1.0) {
    voice->sustained = true;
    if (contact_ > 0.0) voice->release(damperScale, contact_);  // a half pedal
  } else {
    voice->release(damperScale);
  }
}

// The dampers of the keys released under the pedal follow it; those of the keys released while it
// was up stay on their strings (as before the half pedal: pressing the pedal again does not revive
// them), and a key released under the pedal leaves its care once the pedal is fully up. The loss
// moves at the event, between two steps: a kink in the decay, never a step in the signal.
void Synth::setSustain(int value) noexcept {
  const double contact = damperContact(value);
  if (contact == contact_) return;
  contact_ = contact;
  for (auto& keys : voices_)
    for (KeyVoice& v : keys) {
      if (!v.sustained) continue;
      if (v.caught) {  // its damper is the sostenuto's until that lifts
        v.sustained = contact < 1.0;
      } else if (contact < 1.0) {
        v.release(damperScale_ * v.releaseScale, contact);
      } else {
        v.sustained = false;
        v.release(damperScale_ * v.releaseScale);
      }
    }
}

// Going down, it catches the dampers of the keys held then; lifting, it lets them fall on the keys
// released since (onto the sustain pedal's contact for those it also holds).
void Synth::setSostenuto(bool down) noexcept {
  if (down == sostenuto_) return;
  sostenuto_ = down;
  for (auto& keys : voices_)
    for (KeyVoice& v : keys) {
      if (down) {
        v.caught = v.down;
        continue;
      }
      if (!v.caught) continue;
      v.caught = false;
      if (v.down) continue;
      if (!v.sustained)
        v.release(damperScale_ * v.releaseScale);
      else if (contact_ > 0.0)
        v.release(damperScale_ * v.releaseScale, contact_);
    }
}

void Synth::setBend(double fraction) noexcept {
  bend_ = fraction;
  for (size_t p = 0; p < voices_.size(); ++p)
    for (KeyVoice& v : voices_[p])
      if (v.sounding()) v.setBend(bend_ * instruments_[p].bendRange);
}

void Synth::setLiveTail(bool on) noexcept {
  liveTail_ = on;
  for (auto& keys : voices_)
    for (KeyVoice& v : keys) v.setLiveTail(on);
}

void Synth::allSoundOff() noexcept {
  for (auto& keys : voices_)
    for (KeyVoice& v : keys) v.fadeOut();
  // Resting or not: a voice struck just before may still wake it, and the fade covers that too.
  for (auto& body : bodies_)
    if (body && body->fadeLeft == 0) body->fadeLeft = body->fadeSamples;
  std::fill(std::begin(downProgram_), std::end(downProgram_), -1);
}

void Synth::handle(const MidiMessage& m) noexcept {
  switch (m.kind()) {
    case midi::noteOn:
      if (m.data2 > 0) {
        noteOn(m.data1 & 0x7F, m.data2 & 0x7F);
        break;
      }
      [[fallthrough]];
    case midi::noteOff:
      noteOff(m.data1 & 0x7F, m.kind() == midi::noteOff ? m.data2 & 0x7F : 0);
      break;
    case midi::controller:
      switch (m.data1) {
        case midi::sustainPedal:
          setSustain(m.data2 & 0x7F);
          break;
        case midi::sostenutoPedal:
          setSostenuto((m.data2 & 0x7F) >= 64);
          break;
        case midi::softPedal:
          unaCorda_ = (m.data2 & 0x7F) >= 64;
          break;
        case midi::volume: {
          const double v = (m.data2 & 0x7F) / 127.0;
          master_.setVolume(v * v);
          break;
        }
        case midi::allSoundOff:
          allSoundOff();
          break;
        case midi::resetControllers:
          setBend(0.0);
          setSustain(0);
          setSostenuto(false);
          unaCorda_ = false;
          break;
        case midi::allNotesOff:
          for (int note = 0; note < 128; ++note) noteOff(note);
          break;
        default:
          break;
      }
      break;
    case midi::pitchBend:
      setBend((((m.data2 & 0x7F) << 7 | (m.data1 & 0x7F)) - 8192) / 8192.0);
      break;
    case midi::program:
      if (m.data1 < instruments_.size()) {
        program_ = m.data1;
      } else {
        const int p = m.data1 & 0x7F;
        ignoredPrograms_[p / 64] |= std::uint64_t{1} << (p % 64);
      }
      break;
    default:
      break;
  }
}

void Synth::process(std::span<float> left, std::span<float> right,
                    std::span<const SynthEvent> events) noexcept {
  const ScopedFlushToZero ftz;
  const size_t frames = std::min(left.size(), right.size());
  std::fill(left.begin(), left.begin() + frames, 0.0f);
  std::fill(right.begin(), right.begin() + frames, 0.0f);
  size_t done = 0, next = 0;
  while (done < frames) {
    // Events due at or before this sample, then the samples up to the next event (or a whole
    // maxBlock piece): the voices' scratch buffers hold maxBlock samples.
    while (next < events.size() && static_cast<size_t>(std::max(events[next].offset, 0)) <= done)
      handle(events[next++].message);
    size_t until = std::min(frames, done + static_cast<size_t>(maxBlock_));
    if (next < events.size()) until = std::min(until, static_cast<size_t>(events[next].offset));
    render(left.subspan(done, until - done), right.subspan(done, until - done));
    done = until;
  }
  while (next < events.size()) handle(events[next++].message);  // offsets past the block's end
  master_.process(left.first(frames), right.first(frames));
}

}  // namespace hamiltone
