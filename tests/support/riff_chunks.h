// What a WAV file is made of, byte for byte: its contents, and the four-letter ids of the chunks
// of its RIFF container in order (a chunk with a time stamp in it, such as PEAK, shows there).
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace hamiltone::testing {

inline std::string fileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The ids after "RIFF" size "WAVE"; empty when that header is missing. A chunk's body is padded
// to an even length (RIFF), and a size running past the end ends the listing.
inline std::vector<std::string> riffChunkIds(const std::string& bytes) {
  std::vector<std::string> ids;
  if (bytes.size() < 12 || bytes.compare(0, 4, "RIFF") != 0 || bytes.compare(8, 4, "WAVE") != 0)
    return ids;
  std::size_t at = 12;
  while (at + 8 <= bytes.size()) {
    ids.push_back(bytes.substr(at, 4));
    std::uint32_t size = 0;
    for (int i = 3; i >= 0; --i) size = size << 8 | static_cast<unsigned char>(bytes[at + 4 + i]);
    at += 8 + size + (size & 1u);
  }
  return ids;
}

}  // namespace hamiltone::testing
