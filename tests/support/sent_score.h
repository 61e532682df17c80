// The score tests/e2e/midi_sender played, as it logs it: each message with the time it left, and
// the notes it made — each key from its note-on until its damper fell.
#pragma once

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace hamiltone::testing {

// The sender's log: one line per message, "SECONDS HEX …".
struct Sent {
  double seconds;
  std::vector<int> bytes;
};

inline std::vector<Sent> parseLog(const std::string& text) {
  std::vector<Sent> log;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    Sent s{};
    fields >> s.seconds;
    for (std::string hex; fields >> hex;) s.bytes.push_back(std::stoi(hex, nullptr, 16));
    if (!s.bytes.empty()) log.push_back(s);
  }
  return log;
}

// A struck key as the log says it should sound: from its note-on until its damper falls (note-off
// with the pedal up, or the pedal lifting after its note-off).
struct Note {
  int key = 0, program = 0;
  double on = 0.0, damped = std::numeric_limits<double>::infinity();
  bool released = false;
};

inline std::vector<Note> notesOf(const std::vector<Sent>& log) {
  std::vector<Note> notes;
  bool pedal = false;
  int program = 0;
  for (const Sent& s : log) {
    const int type = s.bytes[0] & 0xF0;
    if (type == 0x90 && s.bytes.size() == 3 && s.bytes[2] > 0) {
      notes.push_back({.key = s.bytes[1], .program = program, .on = s.seconds});
    } else if ((type == 0x80 || type == 0x90) && s.bytes.size() == 3) {
      for (Note& n : notes)
        if (n.key == s.bytes[1] && !n.released) {
          n.released = true;
          if (!pedal) n.damped = s.seconds;
        }
    } else if (type == 0xB0 && s.bytes.size() == 3 && s.bytes[1] == 64) {
      pedal = s.bytes[2] >= 64;
      if (!pedal)
        for (Note& n : notes)
          if (n.released && std::isinf(n.damped)) n.damped = s.seconds;
    } else if (type == 0xC0 && s.bytes.size() == 2) {
      program = s.bytes[1];
    }
  }
  return notes;
}

}  // namespace hamiltone::testing
