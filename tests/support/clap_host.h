// A minimal CLAP host for the plugin's tests, on the CLAP headers DPF ships: the entry (of a .clap
// it dlopens, or one linked in), one plugin made from it, activated at a rate and block bounds,
// and processed — stereo out, MIDI and parameter events at their frames — with the params and
// state extensions. No GUI, no host extensions (the plugin must cope without them, as it must in
// a host that offers few). process() allocates nothing, so a real-time sanitiser can watch it.
#pragma once

#include <dlfcn.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "clap/entry.h"
#include "clap/ext/audio-ports.h"
#include "clap/ext/latency.h"
#include "clap/ext/note-ports.h"
#include "clap/ext/params.h"
#include "clap/ext/state.h"
#include "clap/plugin-factory.h"
#include "clap/process.h"

namespace hamiltone::testing {

// An input event as the host hands it over: the header, then a MIDI message or a parameter value.
struct ClapEvent {
  union {
    clap_event_header_t header;
    clap_event_midi_t midi;
    clap_event_param_value_t param;
  };

  static ClapEvent midiAt(uint32_t frame, uint8_t status, uint8_t data1, uint8_t data2) {
    ClapEvent e;
    e.midi = {{sizeof(clap_event_midi_t), frame, CLAP_CORE_EVENT_SPACE_ID, CLAP_EVENT_MIDI, 0},
              0,
              {status, data1, data2}};
    return e;
  }
  static ClapEvent paramAt(uint32_t frame, clap_id id, double value) {
    ClapEvent e;
    e.param = {{sizeof(clap_event_param_value_t), frame, CLAP_CORE_EVENT_SPACE_ID,
                CLAP_EVENT_PARAM_VALUE, 0},
               id,
               nullptr,
               -1,
               -1,
               -1,
               -1,
               value};
    return e;
  }
};

// The plugin entry: dlopen()ed from a .clap file (closed again at the end), or one linked in.
class ClapLibrary {
 public:
  explicit ClapLibrary(const std::string& path) : handle_(::dlopen(path.c_str(), RTLD_NOW)) {
    if (!handle_) throw std::runtime_error("dlopen " + path + ": " + ::dlerror());
    entry_ = static_cast<const clap_plugin_entry_t*>(::dlsym(handle_, "clap_entry"));
    if (!entry_) throw std::runtime_error(path + " has no clap_entry");
    init(path);
  }
  ClapLibrary(const clap_plugin_entry_t& entry, const std::string& path) : entry_(&entry) {
    init(path);
  }
  ~ClapLibrary() {
    entry_->deinit();
    if (handle_) ::dlclose(handle_);
  }
  ClapLibrary(const ClapLibrary&) = delete;
  ClapLibrary& operator=(const ClapLibrary&) = delete;

  const clap_plugin_factory_t& factory() const { return *factory_; }

 private:
  void init(const std::string& path) {
    if (!entry_->init(path.c_str())) throw std::runtime_error("clap_entry.init failed: " + path);
    factory_ =
        static_cast<const clap_plugin_factory_t*>(entry_->get_factory(CLAP_PLUGIN_FACTORY_ID));
    if (!factory_) throw std::runtime_error(path + " has no plugin factory");
  }

  void* handle_ = nullptr;
  const clap_plugin_entry_t* entry_ = nullptr;
  const clap_plugin_factory_t* factory_ = nullptr;
};

class ClapInstance {
 public:
  ClapInstance(const ClapLibrary& library, const char* id) {
    plugin_ = library.factory().create_plugin(&library.factory(), &host_, id);
    if (!plugin_ || !plugin_->init(plugin_))
      throw std::runtime_error("cannot make plugin " + std::string(id));
    params_ = extension<clap_plugin_params_t>(CLAP_EXT_PARAMS);
    state_ = extension<clap_plugin_state_t>(CLAP_EXT_STATE);
  }
  ~ClapInstance() {
    deactivate();
    plugin_->destroy(plugin_);
  }
  ClapInstance(const ClapInstance&) = delete;
  ClapInstance& operator=(const ClapInstance&) = delete;

  template <class T>
  const T* extension(const char* id) const {
    return static_cast<const T*>(plugin_->get_extension(plugin_, id));
  }
  const clap_plugin_t& plugin() const { return *plugin_; }

  // Activates and starts processing, for blocks of minFrames … maxFrames.
  bool activate(double rate, uint32_t minFrames, uint32_t maxFrames) {
    deactivate();
    active_ = plugin_->activate(plugin_, rate, minFrames, maxFrames);
    return active_ && plugin_->start_processing(plugin_);
  }
  void deactivate() {
    if (!active_) return;
    plugin_->stop_processing(plugin_);
    plugin_->deactivate(plugin_);
    active_ = false;
  }

  // One process call: writes left.size() frames; `events` sorted by frame, each inside the block.
  clap_process_status process(std::span<float> left, std::span<float> right,
                              std::span<const ClapEvent> events) {
    float* channels[2] = {left.data(), right.data()};
    clap_audio_buffer_t out{channels, nullptr, 2, 0, 0};
    EventList list{events};
    const clap_input_events_t in{&list, &EventList::size, &EventList::get};
    const clap_output_events_t discard{
        nullptr, [](const clap_output_events_t*, const clap_event_header_t*) { return true; }};
    const clap_process_t process{
        steadyTime_, static_cast<uint32_t>(left.size()), nullptr, nullptr, &out, 0, 1, &in,
        &discard};
    steadyTime_ += static_cast<int64_t>(left.size());
    return plugin_->process(plugin_, &process);
  }

  double param(clap_id id) const {
    double value = 0.0;
    if (!params_->get_value(plugin_, id, &value)) throw std::runtime_error("no parameter");
    return value;
  }

  std::string saveState() const {
    std::string bytes;
    const clap_ostream_t out{&bytes, [](const clap_ostream_t* s, const void* data, uint64_t size) {
                               static_cast<std::string*>(s->ctx)->append(
                                   static_cast<const char*>(data), size);
                               return static_cast<int64_t>(size);
                             }};
    if (!state_->save(plugin_, &out)) throw std::runtime_error("state save failed");
    return bytes;
  }
  bool loadState(const std::string& bytes) {
    Reader reader{bytes, 0};
    const clap_istream_t in{&reader, [](const clap_istream_t* s, void* data, uint64_t size) {
                              auto* r = static_cast<Reader*>(s->ctx);
                              const uint64_t n = std::min<uint64_t>(size, r->bytes.size() - r->at);
                              std::memcpy(data, r->bytes.data() + r->at, n);
                              r->at += n;
                              return static_cast<int64_t>(n);
                            }};
    return state_->load(plugin_, &in);
  }

 private:
  struct EventList {
    std::span<const ClapEvent> events;
    static uint32_t size(const clap_input_events_t* list) {
      return static_cast<uint32_t>(static_cast<const EventList*>(list->ctx)->events.size());
    }
    static const clap_event_header_t* get(const clap_input_events_t* list, uint32_t i) {
      return &static_cast<const EventList*>(list->ctx)->events[i].header;
    }
  };
  struct Reader {
    const std::string& bytes;
    uint64_t at;
  };

  const clap_host_t host_{CLAP_VERSION_INIT,
                          nullptr,
                          "hamiltone tests",
                          "hamiltone",
                          "",
                          "1",
                          [](const clap_host_t*, const char*) -> const void* { return nullptr; },
                          [](const clap_host_t*) {},
                          [](const clap_host_t*) {},
                          [](const clap_host_t*) {}};
  const clap_plugin_t* plugin_ = nullptr;
  const clap_plugin_params_t* params_ = nullptr;
  const clap_plugin_state_t* state_ = nullptr;
  int64_t steadyTime_ = 0;
  bool active_ = false;
};

}  // namespace hamiltone::testing
