// The end-to-end test's MIDI keyboard: a JACK MIDI client (RtMidi) that waits for the player's
// input port, connects to it and plays a fixed score on the steady clock. Each message is logged to
// stdout as it leaves — "SECONDS HEX HEX …", seconds from the start of the score — so that the test
// compares what it hears with what was actually sent, not with what was meant to be.
//
// Usage: midi_sender PORT_SUBSTRING [WAIT_SECONDS]. Exit 0 when the score was sent, 1 when no port
// matched within the wait (10 s by default), 2 on bad arguments.
#include <RtMidi.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct Cue {
  double seconds;
  std::vector<unsigned char> bytes;
};

// Program 0 is the grand piano and program 1 the paper's C3 string (the test loads them in that
// order). The notes never overlap, so that each one's pitch can be measured alone: a key is damped
// (note-off, or pedal up) at least 0.5 s before the next strike, in which its damper (T60 0.46 …
// 0.63 s on these keys) takes it more than 40 dB down. E4 is released while the pedal is down and
// rings on through the sysex until the pedal lifts.
const std::vector<Cue> kScore = {
    {0.0, {0xC0, 0}},
    {0.5, {0x90, 60, 100}},  // C4 forte
    {1.5, {0x80, 60, 0}},
    {1.9, {0xB0, 64, 127}},                       // pedal down
    {2.0, {0x90, 64, 60}},                        // E4 mezzo-piano
    {2.5, {0x80, 64, 0}},                         // held by the pedal
    {2.7, {0xF0, 0x7E, 0x7F, 0x06, 0x01, 0xF7}},  // identity request: the player ignores sysex
    {3.5, {0xB0, 64, 0}},                         // pedal up: E4 is damped
    {4.0, {0xC0, 1}},
    {4.5, {0x90, 48, 100}},  // C3 on the paper's string
    {5.5, {0x80, 48, 0}},
    {6.0, {0x90, 52, 80}},  // E3
    {7.0, {0x80, 52, 0}},
    {7.5, {0xC0, 0}},
    {8.0, {0x90, 69, 80}},  // A4 on the piano again
    {9.0, {0x80, 69, 0}},
};

// The first output port whose name contains `wanted`, or −1.
int findPort(RtMidiOut& out, const std::string& wanted) {
  const unsigned count = out.getPortCount();
  for (unsigned i = 0; i < count; ++i)
    if (out.getPortName(i).find(wanted) != std::string::npos) return static_cast<int>(i);
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: midi_sender PORT_SUBSTRING [WAIT_SECONDS]\n");
    return 2;
  }
  const std::string wanted = argv[1];
  const double wait = argc == 3 ? std::atof(argv[2]) : 10.0;
  try {
    RtMidiOut out(RtMidi::UNIX_JACK, "hamiltone-sender");
    const auto deadline = Clock::now() + std::chrono::duration<double>(wait);
    int port = findPort(out, wanted);
    while (port < 0 && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      port = findPort(out, wanted);
    }
    if (port < 0) {
      std::fprintf(stderr, "midi_sender: no JACK MIDI port matching \"%s\"\n", wanted.c_str());
      return 1;
    }
    out.openPort(static_cast<unsigned>(port), "out");
    // The connection is made by the server's graph thread; give it a few cycles to take effect.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));

    const Clock::time_point start = Clock::now();
    for (const Cue& cue : kScore) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(cue.seconds)));
      const Clock::time_point sent = Clock::now();
      out.sendMessage(&cue.bytes);
      std::printf("%.6f", std::chrono::duration<double>(sent - start).count());
      for (unsigned char b : cue.bytes) std::printf(" %02X", b);
      std::printf("\n");
    }
    std::fflush(stdout);
    // Messages leave in the next process cycle of the sender's JACK client: let the last one go.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  } catch (const RtMidiError& e) {
    std::fprintf(stderr, "midi_sender: %s\n", e.getMessage().c_str());
    return 1;
  }
  return 0;
}
