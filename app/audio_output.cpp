// AudioOutput on RtAudio 5: API by name, devices by index, a float32 interleaved stereo stream,
// underflows counted, and every RtAudioError turned into an AudioError that says what exists.
#include "audio_output.h"

#include <RtAudio.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>

#include "quiet_stderr.h"

namespace hamiltone::app {

struct AudioOutput::Impl {
  std::unique_ptr<RtAudio> audio;
  Render render;
  std::atomic<long> underruns{0};
  bool started = false, stopped = false;  // main thread only
  std::atomic<bool> failed{false};        // set by RtAudio's error callback
  char failure[256] = {};                 // its message, written before `failed` is set
};

namespace {

// RtAudio 5's error callback has no user pointer: the one open stream's Impl, for it.
std::atomic<AudioOutput::Impl*> errorSink{nullptr};

// Called by RtAudio on its own threads for a stream error (not on the real-time path).
// RtAudio 5's JACK stream cannot follow a change of the server's buffer size (jack_bufsize, or
// PipeWire changing its quantum): from then on it calls our callback no more and reports only a
// warning each period. Taken as the stream's end, so that the player says so and stops.
void streamError(RtAudioError::Type type, const std::string& text) {
  const bool bufferChanged = text.find("buffer size has changed") != std::string::npos;
  if ((type == RtAudioError::WARNING || type == RtAudioError::DEBUG_WARNING) && !bufferChanged)
    return;
  AudioOutput::Impl* impl = errorSink.load();
  if (!impl || impl->failed.load()) return;
  std::snprintf(impl->failure, sizeof impl->failure, "%s",
                bufferChanged
                    ? "the JACK server's buffer size changed while playing (jack_bufsize, "
                      "or PipeWire's quantum), which the stream cannot follow; start "
                      "hamiltone-play again to play at the new size"
                    : text.c_str());
  impl->failed.store(true);
}

int callback(void* out, void*, unsigned frames, double, RtAudioStreamStatus status, void* user) {
  auto* impl = static_cast<AudioOutput::Impl*>(user);
  const bool underrun = (status & RTAUDIO_OUTPUT_UNDERFLOW) != 0;
  if (underrun) impl->underruns.fetch_add(1, std::memory_order_relaxed);
  impl->render(static_cast<float*>(out), static_cast<int>(frames), underrun);
  return 0;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "none" : s;
}

std::string deviceList(const std::vector<AudioDevice>& devices) {
  std::string s;
  for (const AudioDevice& d : devices)
    s += (s.empty() ? "" : "; ") + std::to_string(d.id) + ": " + d.name +
         (d.isDefault ? " (default)" : "");
  return s.empty() ? "none" : s;
}

}  // namespace

std::vector<std::string> AudioOutput::compiledApis() {
  std::vector<RtAudio::Api> apis;
  RtAudio::getCompiledApi(apis);
  std::vector<std::string> names;
  for (RtAudio::Api api : apis)
    if (api != RtAudio::RTAUDIO_DUMMY) names.push_back(RtAudio::getApiName(api));
  return names;
}

AudioOutput::AudioOutput(const std::string& api) : impl_(std::make_unique<Impl>()), api_(api) {
  const RtAudio::Api id = RtAudio::getCompiledApiByName(api);
  if (id == RtAudio::UNSPECIFIED || id == RtAudio::RTAUDIO_DUMMY)
    throw AudioError("audio API \"" + api +
                     "\" is not available; this build has: " + joined(compiledApis()));
  try {
    const QuietStderr quiet;
    impl_->audio = std::make_unique<RtAudio>(id);
    impl_->audio->showWarnings(false);
  } catch (const RtAudioError& e) {
    throw AudioError("audio API " + api + ": " + e.getMessage());
  }
}

AudioOutput::~AudioOutput() {
  AudioOutput::Impl* self = impl_.get();
  errorSink.compare_exchange_strong(self, nullptr);
  try {
    stop();
    if (impl_->audio && impl_->audio->isStreamOpen()) impl_->audio->closeStream();
  } catch (const RtAudioError&) {
  }
}

std::vector<AudioDevice> AudioOutput::devices() {
  std::vector<AudioDevice> list;
  const QuietStderr quiet;  // probing a device that is busy or gone prints through ALSA/JACK
  try {
    const unsigned count = impl_->audio->getDeviceCount();
    for (unsigned i = 0; i < count; ++i) {
      const RtAudio::DeviceInfo info = impl_->audio->getDeviceInfo(i);
      if (!info.probed || info.outputChannels < 1) continue;
      list.push_back({static_cast<int>(i), info.name, static_cast<int>(info.outputChannels),
                      info.isDefaultOutput, info.sampleRates, info.preferredSampleRate});
    }
  } catch (const RtAudioError&) {
  }
  return list;
}

AudioDevice AudioOutput::device(int id) {
  for (AudioDevice& d : devices())
    if (d.id == id) return d;
  throw AudioError("device " + std::to_string(id) + " of API " + api_ + " is gone");
}

unsigned chooseSampleRate(unsigned requested, const AudioDevice& device) {
  const std::vector<unsigned>& rates = device.sampleRates;
  if (rates.empty() || std::find(rates.begin(), rates.end(), requested) != rates.end())
    return requested;
  if (device.preferredRate > 0) return device.preferredRate;
  return *std::min_element(rates.begin(), rates.end(), [requested](unsigned a, unsigned b) {
    return std::labs(long(a) - long(requested)) < std::labs(long(b) - long(requested));
  });
}

int AudioOutput::resolve(int device) {
  const std::vector<AudioDevice> available = devices();
  if (available.empty())
    throw AudioError("no audio output device for API " + api_ +
                     (api_ == "jack" ? " (is a JACK server running?)" : "") +
                     "; APIs in this build: " + joined(compiledApis()));
  int chosen = device;
  if (chosen < 0) {
    chosen = available.front().id;
    for (const AudioDevice& d : available)
      if (d.isDefault) chosen = d.id;
  }
  for (const AudioDevice& d : available)
    if (d.id == chosen) return chosen;
  throw AudioError("--device " + std::to_string(device) + ": no such output device for API " +
                   api_ + "; devices: " + deviceList(available));
}

void AudioOutput::open(int device, unsigned sampleRate, unsigned& bufferFrames, Render render) {
  const int chosen = resolve(device);
  impl_->render = std::move(render);
  RtAudio::StreamParameters out;
  out.deviceId = static_cast<unsigned>(chosen);
  out.nChannels = 2;
  RtAudio::StreamOptions options;
  options.streamName = "hamiltone";
  options.flags = RTAUDIO_SCHEDULE_REALTIME;
  try {
    const QuietStderr quiet;
    errorSink.store(impl_.get());
    impl_->audio->openStream(&out, nullptr, RTAUDIO_FLOAT32, sampleRate, &bufferFrames, &callback,
                             impl_.get(), &options, &streamError);
  } catch (const RtAudioError& e) {
    throw AudioError("cannot open device " + std::to_string(chosen) + " of API " + api_ + " at " +
                     std::to_string(sampleRate) + " Hz: " + e.getMessage() +
                     "; devices: " + deviceList(devices()));
  }
}

unsigned AudioOutput::streamRate() const { return impl_->audio->getStreamSampleRate(); }

void AudioOutput::start() {
  try {
    impl_->audio->startStream();
    impl_->started = true;
  } catch (const RtAudioError& e) {
    throw AudioError("cannot start the audio stream: " + e.getMessage());
  }
}

// RtAudio's JACK stopStream() waits until the callback has run twice more without calling ours,
// so that jack_deactivate() — which cancels the process thread asynchronously — never finds our
// render running (cancelled inside it, a noexcept function, the program would terminate). But
// after a stream failure (the server's buffer size changed, see streamError) the callback is
// called no more and that wait would never end: then abortStream(), which skips it; our render is
// not running then.
void AudioOutput::stop() {
  impl_->stopped = true;
  if (!impl_->audio || !impl_->audio->isStreamOpen() || !impl_->audio->isStreamRunning()) return;
  if (impl_->failed.load())
    impl_->audio->abortStream();
  else
    impl_->audio->stopStream();
}

long AudioOutput::underruns() const { return impl_->underruns.load(); }

bool AudioOutput::lost() const {
  if (!impl_->started || impl_->stopped) return false;
  return impl_->failed.load() || !impl_->audio->isStreamOpen() || !impl_->audio->isStreamRunning();
}

std::string AudioOutput::lostReason() const {
  if (impl_->failed.load()) return impl_->failure;
  return api_ == "jack" ? "the JACK server shut this client down (it stopped, or went away)"
                        : "the audio stream stopped by itself (the device went away?)";
}

}  // namespace hamiltone::app
