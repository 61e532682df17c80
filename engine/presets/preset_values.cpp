// A read preset's values: a parameter's setting or default, and its value at a key between the
// [[key]] anchors.
#include "presets/preset_values.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hamiltone {

const Parameter& PresetValues::row(std::string_view name) const {
  const Parameter* p = model ? findParameter(name, *model) : findParameter(name);
  if (!p) throw std::logic_error("preset loader: no parameter " + std::string(name));
  return *p;
}

const Setting* PresetValues::setting(std::string_view name) const {
  const auto it = settings.find(name);
  return it == settings.end() ? nullptr : &it->second;
}

double PresetValues::number(std::string_view name) const {
  if (const Setting* s = setting(name)) return s->number;
  if (name == "plate.reference_note") return number("lowest_note");
  return defaultNumber(row(name));
}

std::string PresetValues::word(std::string_view name) const {
  if (const Setting* s = setting(name)) return s->word;
  return std::string(row(name).defaultText);
}

bool PresetValues::anchored(const Parameter& p) const {
  return std::any_of(anchors.begin(), anchors.end(),
                     [&](const Anchor& a) { return a.values.count(p.name) > 0; });
}

// The value at `note`: the anchors that set the parameter define it (interpolated between them,
// held beyond them); without any, the section's value or the default holds at every key.
double PresetValues::atKey(const Parameter& p, int note) const {
  const Anchor *below = nullptr, *above = nullptr;
  for (const Anchor& a : anchors) {
    if (!a.values.count(p.name)) continue;
    if (a.note <= note)
      below = &a;
    else if (!above)
      above = &a;
  }
  if (!below && !above) return number(p.name);
  if (!below) return above->values.at(p.name).number;
  const double a = below->values.at(p.name).number;
  if (!above || below->note == note || p.type == ParameterType::integer) return a;
  const double b = above->values.at(p.name).number;
  const double t = static_cast<double>(note - below->note) / (above->note - below->note);
  if (p.min <= 0.0) return a + t * (b - a);
  if (!std::isfinite(a) || !std::isfinite(b)) return INFINITY;
  return a * std::pow(b / a, t);
}

}  // namespace hamiltone
