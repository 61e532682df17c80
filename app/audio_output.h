// The audio device, behind a thin adapter: RtAudio 5 (Debian's; errors are exceptions, devices
// are indices) today, RtAudio 6 (error codes, device IDs) later, without touching the engine.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace hamiltone::app {

// No API, no device, or a device that refuses the stream: the message says which and what exists.
struct AudioError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct AudioDevice {
  int id = 0;  // what --device takes
  std::string name;
  int outputChannels = 0;
  bool isDefault = false;
  // The rates it runs at (a JACK server: its one rate), and the one it prefers (0: none said).
  std::vector<unsigned> sampleRates;
  unsigned preferredRate = 0;
};

// The rate to open `device` at when `requested` is asked for: that one, if the device runs at it
// or says nothing; otherwise the device's preferred rate (a JACK server's, PipeWire's JACK's), or
// the one nearest to `requested` it lists.
unsigned chooseSampleRate(unsigned requested, const AudioDevice& device);

class AudioOutput {
 public:
  // Interleaved stereo float frames to fill; `underrun` when the device reported an underflow
  // since the last call. Runs on the audio thread.
  using Render = std::function<void(float* out, int frames, bool underrun)>;

  static std::vector<std::string> compiledApis();  // "jack", "alsa", "pulse" …
  // Throws AudioError naming the API and the ones compiled in.
  explicit AudioOutput(const std::string& api);
  ~AudioOutput();

  std::vector<AudioDevice> devices();
  AudioDevice device(int id);  // one of devices(); AudioError if there is no such device
  // The device --device names (−1: the default), or AudioError naming the APIs or the devices.
  int resolve(int device);
  // Opens a stereo float stream at `sampleRate`; bufferFrames is a request the device may
  // change. Throws AudioError listing the devices.
  void open(int device, unsigned sampleRate, unsigned& bufferFrames, Render render);
  unsigned streamRate() const;  // the open stream's rate
  void start();
  void stop();  // waits for the callback to finish; safe to call twice
  long underruns() const;
  // Whether the started stream ended without stop(): the server went away (JACK shuts its clients
  // down, and RtAudio then closes the stream) or RtAudio reported an error. From the main thread,
  // polled; lostReason() says what happened.
  bool lost() const;
  std::string lostReason() const;
  std::string api() const { return api_; }

  struct Impl;  // RtAudio's, and what its C callback reaches

 private:
  std::unique_ptr<Impl> impl_;
  std::string api_;
};

}  // namespace hamiltone::app
