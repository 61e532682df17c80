// Anchor keys of docs/instrument-data.md §1.1 (RT-425 "wrapped" plan; C8 from the
// "unwrapped" plan, §1.3) and E2/F2 either side of the bass-bridge break (§1.2).
#include "instruments/piano_scale.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace hamiltone {

namespace {

struct Anchor {
  int midi;
  double length;    // m
  double diameter;  // core, mm
  double rhoA;      // g/m, winding included
  double tension;   // N
};

// §1.1 rows (MIDI 24 … 107), E2 and F2 from §1.2, C8 from §1.3.
constexpr std::array<Anchor, 18> kPlan{{
    {24, 2.007, 1.480, 99.413, 1722},
    {33, 1.762, 1.207, 31.566, 1190},
    {36, 1.602, 1.051, 20.751, 915},
    {40, 1.378, 0.937, 14.300, 741},
    {41, 1.837, 1.117, 7.729, 799},
    {45, 1.482, 1.071, 7.072, 754},
    {48, 1.259, 1.063, 6.967, 759},
    {57, 0.773, 1.027, 6.503, 755},
    {60, 0.657, 1.006, 6.240, 741},
    {69, 0.404, 0.947, 5.529, 701},
    {72, 0.344, 0.932, 5.355, 696},
    {81, 0.211, 0.901, 5.005, 697},
    {84, 0.180, 0.891, 4.895, 697},
    {93, 0.111, 0.850, 4.454, 683},
    {96, 0.095, 0.831, 4.258, 670},
    {105, 0.058, 0.761, 3.570, 606},
    {107, 0.052, 0.743, 3.404, 588},
    {108, 0.0498, 0.653, 2.627, 458},
}};

constexpr double kSteelYoung = 2.02e11;  // Pa, as in RT-425

double geometric(double a, double b, double t) { return a * std::pow(b / a, t); }

}  // namespace

double equalTemperament(int midiNote, double a4Hz) {
  return a4Hz * std::pow(2.0, (midiNote - 69) / 12.0);
}

StringPhysics pianoString(int midiNote) {
  if (midiNote < 21 || midiNote > 108)
    throw std::invalid_argument("note = " + std::to_string(midiNote) +
                                ": the piano's keys are MIDI 21 (A0) to 108 (C8)");
  const int key = std::max(midiNote, kPlan.front().midi);
  size_t i = 0;
  while (i + 2 < kPlan.size() && kPlan[i + 1].midi <= key) ++i;
  const Anchor& a = kPlan[i];
  const Anchor& b = kPlan[i + 1];
  const double t = static_cast<double>(key - a.midi) / (b.midi - a.midi);
  const double d = geometric(a.diameter, b.diameter, t) * 1e-3;
  StringPhysics p;
  p.length = geometric(a.length, b.length, t);
  p.area = std::numbers::pi * d * d / 4.0;
  p.density = geometric(a.rhoA, b.rhoA, t) * 1e-3 / p.area;
  p.young = kSteelYoung;
  p.tension = geometric(a.tension, b.tension, t);
  p.inertia = std::numbers::pi * std::pow(d, 4) / 64.0;
  return p;
}

}  // namespace hamiltone
