// A Standard MIDI File writer for the reader's tests: chunks, variable-length numbers and events
// written byte for byte as given, so that a test builds exactly the file — valid or not — it means.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string_view>
#include <vector>

namespace hamiltone::testing {

using Bytes = std::vector<std::uint8_t>;

// `count` bytes of `value`, most significant first.
inline void appendBigEndian(Bytes& out, std::uint32_t value, int count) {
  for (int i = count - 1; i >= 0; --i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

// A variable-length number (≤ 0x0FFFFFFF): 7 bits a byte, most significant first, the top bit
// set on all bytes but the last.
inline void appendVariableLength(Bytes& out, std::uint32_t value) {
  int count = 1;
  while (count < 4 && (value >> (7 * count)) != 0) ++count;
  for (int i = count - 1; i >= 0; --i)
    out.push_back(static_cast<std::uint8_t>(((value >> (7 * i)) & 0x7F) | (i > 0 ? 0x80 : 0)));
}

// The events of one track, each a delta time in ticks then its bytes. A channel message written
// without its status byte uses running status.
class TrackWriter {
 public:
  TrackWriter& event(std::uint32_t delta, std::initializer_list<std::uint8_t> bytes) {
    appendVariableLength(bytes_, delta);
    bytes_.insert(bytes_.end(), bytes);
    return *this;
  }
  TrackWriter& meta(std::uint32_t delta, std::uint8_t type, const Bytes& data) {
    event(delta, {0xFF, type});
    appendVariableLength(bytes_, static_cast<std::uint32_t>(data.size()));
    bytes_.insert(bytes_.end(), data.begin(), data.end());
    return *this;
  }
  TrackWriter& tempo(std::uint32_t delta, std::uint32_t microsPerQuarter) {
    Bytes data;
    appendBigEndian(data, microsPerQuarter, 3);
    return meta(delta, 0x51, data);
  }
  // `kind` 0xF0 (a sysex message) or 0xF7 (an escape); `data` follows the length.
  TrackWriter& sysex(std::uint32_t delta, std::uint8_t kind, const Bytes& data) {
    event(delta, {kind});
    appendVariableLength(bytes_, static_cast<std::uint32_t>(data.size()));
    bytes_.insert(bytes_.end(), data.begin(), data.end());
    return *this;
  }
  TrackWriter& endOfTrack(std::uint32_t delta = 0) { return meta(delta, 0x2F, {}); }

  const Bytes& bytes() const { return bytes_; }

 private:
  Bytes bytes_;
};

// A chunk: its 4-character type, its length, its data.
inline Bytes chunk(std::string_view type, const Bytes& data) {
  Bytes out(type.begin(), type.end());
  appendBigEndian(out, static_cast<std::uint32_t>(data.size()), 4);
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

// The MThd chunk.
inline Bytes header(int format, int tracks, int division) {
  Bytes data;
  for (int field : {format, tracks, division})
    appendBigEndian(data, static_cast<std::uint32_t>(field), 2);
  return chunk("MThd", data);
}

inline Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

// A whole file: the header, then one MTrk chunk per track.
inline Bytes midiFile(int format, int division, std::initializer_list<TrackWriter> tracks) {
  Bytes out = header(format, static_cast<int>(tracks.size()), division);
  for (const TrackWriter& track : tracks) {
    const Bytes c = chunk("MTrk", track.bytes());
    out.insert(out.end(), c.begin(), c.end());
  }
  return out;
}

}  // namespace hamiltone::testing
