// The end-to-end test's MIDI keyboard: a JACK MIDI client on libjack that waits for the player's
// input port, connects to it and plays a fixed score on the steady clock. Each message is logged to
// stdout as it leaves — "SECONDS HEX HEX …", seconds from the start of the score — so that the test
// compares what it hears with what was actually sent, not with what was meant to be.
//
// It talks to libjack itself, as the player's input does, rather than through RtMidi: RtMidi's JACK
// output once died of SIGSEGV on its way out in a CI run (its client torn down around a running
// process callback). Here the main thread hands messages to the process callback through a
// lock-free ring buffer, and the client is deactivated before it is closed.
//
// Usage: midi_sender PORT_SUBSTRING [WAIT_SECONDS]. Exit 0 when the score was sent, 1 when no port
// matched within the wait (10 s by default) or the server failed, 2 on bad arguments.
#include <jack/jack.h>
#include <jack/midiport.h>
#include <jack/ringbuffer.h>

#include <atomic>
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

// The client: its output port, the ring buffer of messages waiting for the next cycle (each a
// length byte, then the bytes), and the cycles the callback has run.
struct Sender {
  jack_client_t* client = nullptr;
  jack_port_t* port = nullptr;
  jack_ringbuffer_t* queue = nullptr;
  std::atomic<unsigned long> cycles{0};
  std::atomic<bool> serverGone{false};
};

// The process callback: every message waiting goes out at the start of this cycle, in order.
int process(jack_nframes_t frames, void* arg) {
  auto* s = static_cast<Sender*>(arg);
  void* buffer = jack_port_get_buffer(s->port, frames);
  jack_midi_clear_buffer(buffer);
  unsigned char size = 0;
  unsigned char bytes[255];
  while (jack_ringbuffer_peek(s->queue, reinterpret_cast<char*>(&size), 1) == 1 &&
         jack_ringbuffer_read_space(s->queue) >= 1u + size) {
    jack_ringbuffer_read_advance(s->queue, 1);
    jack_ringbuffer_read(s->queue, reinterpret_cast<char*>(bytes), size);
    jack_midi_event_write(buffer, 0, bytes, size);
  }
  s->cycles.fetch_add(1, std::memory_order_release);
  return 0;
}

void serverGone(void* arg) { static_cast<Sender*>(arg)->serverGone.store(true); }

// The first MIDI input port whose name contains `wanted`, or "".
std::string findPort(jack_client_t* client, const std::string& wanted) {
  std::string found;
  const char** ports = jack_get_ports(client, nullptr, JACK_DEFAULT_MIDI_TYPE, JackPortIsInput);
  for (const char** p = ports; p && *p && found.empty(); ++p)
    if (std::string(*p).find(wanted) != std::string::npos) found = *p;
  jack_free(ports);
  return found;
}

// Waits until the callback has run `n` more cycles, or the server is gone; false then.
bool awaitCycles(const Sender& s, unsigned long n) {
  const unsigned long until = s.cycles.load(std::memory_order_acquire) + n;
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (s.cycles.load(std::memory_order_acquire) < until) {
    if (s.serverGone.load() || Clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

int play(Sender& s, const std::string& wanted, double wait) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(wait);
  std::string target = findPort(s.client, wanted);
  while (target.empty() && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    target = findPort(s.client, wanted);
  }
  if (target.empty()) {
    std::fprintf(stderr, "midi_sender: no JACK MIDI port matching \"%s\"\n", wanted.c_str());
    return 1;
  }
  if (const int rc = jack_connect(s.client, jack_port_name(s.port), target.c_str()); rc != 0) {
    std::fprintf(stderr, "midi_sender: jack_connect to \"%s\" failed (%d)\n", target.c_str(), rc);
    return 1;
  }
  // The connection is made by the server's graph thread; give it a few cycles to take effect.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));

  const Clock::time_point start = Clock::now();
  for (const Cue& cue : kScore) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(cue.seconds)));
    const auto size = static_cast<unsigned char>(cue.bytes.size());
    if (jack_ringbuffer_write_space(s.queue) < 1u + size) {
      std::fprintf(stderr, "midi_sender: the process callback has stopped taking messages\n");
      return 1;
    }
    const Clock::time_point sent = Clock::now();
    jack_ringbuffer_write(s.queue, reinterpret_cast<const char*>(&size), 1);
    jack_ringbuffer_write(s.queue, reinterpret_cast<const char*>(cue.bytes.data()), size);
    std::printf("%.6f", std::chrono::duration<double>(sent - start).count());
    for (unsigned char b : cue.bytes) std::printf(" %02X", b);
    std::printf("\n");
  }
  std::fflush(stdout);
  // The last message leaves in the next cycle; two more make sure the server has moved it on.
  if (!awaitCycles(s, 3)) {
    std::fprintf(stderr, "midi_sender: the JACK server stopped before the score had left\n");
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: midi_sender PORT_SUBSTRING [WAIT_SECONDS]\n");
    return 2;
  }
  const std::string wanted = argv[1];
  const double wait = argc == 3 ? std::atof(argv[2]) : 10.0;

  Sender s;
  jack_status_t status{};
  s.client = jack_client_open("hamiltone-sender", JackNoStartServer, &status);
  if (!s.client) {
    std::fprintf(stderr, "midi_sender: no JACK server (jack_client_open status 0x%x)\n",
                 static_cast<unsigned>(status));
    return 1;
  }
  s.queue = jack_ringbuffer_create(4096);
  s.port = jack_port_register(s.client, "out", JACK_DEFAULT_MIDI_TYPE, JackPortIsOutput, 0);
  jack_set_process_callback(s.client, &process, &s);
  jack_on_shutdown(s.client, &serverGone, &s);
  int rc = 1;
  if (!s.port || !s.queue)
    std::fprintf(stderr, "midi_sender: could not register the output port\n");
  else if (jack_activate(s.client) != 0)
    std::fprintf(stderr, "midi_sender: jack_activate failed\n");
  else {
    rc = play(s, wanted, wait);
    jack_deactivate(s.client);  // the callback stops before the client and the queue go
  }
  jack_client_close(s.client);
  if (s.queue) jack_ringbuffer_free(s.queue);
  return rc;
}
