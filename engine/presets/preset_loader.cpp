// Reading a preset: the TOML syntax (toml++), every key against the parameter table (name, type,
// range, model, per key), the command line's --set over the file's keys and the bounds one
// parameter sets another; then the model's builder (string_builder.h, plate_builder.h) makes the
// Instrument and checks its voices at a few keys, whose complaints are pointed at the settings.
#include "presets/preset_loader.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>

#include "presets/parameters.h"
#include "presets/plate_builder.h"
#include "presets/preset_values.h"
#include "presets/string_builder.h"
#include "util/format_number.h"

namespace hamiltone {

namespace {

constexpr size_t kMaxBytes = size_t{1} << 20;
constexpr size_t kMaxAnchors = 128;
constexpr size_t kMaxLines = 100;     // lines in a PresetError, the last one counting the rest
constexpr size_t kMaxKept = 1000;     // errors kept for sorting; beyond, only counted
constexpr size_t kMaxSuggested = 64;  // longer names get no "did you mean"
constexpr size_t kMaxShown = 40;      // bytes of a name or text value quoted in a message
constexpr size_t kMaxText = 200;      // bytes of a text parameter

Place placeOf(const toml::source_region& region) {
  if (region.begin.line == 0) return {};
  return {.line = static_cast<long>(region.begin.line),
          .column = static_cast<long>(region.begin.column)};
}

// Where a value came from, and how an error line names it: "key[C3].string.tension_N = 759".
struct Blame {
  Place place;
  std::string text;
};

}  // namespace

std::string shownInMessage(std::string_view s, bool quoted) {
  size_t n = std::min(s.size(), kMaxShown);
  while (n > 0 && n < s.size() && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
  std::string out = quoted ? "\"" : "";
  for (char c : s.substr(0, n)) {
    if (quoted && (c == '"' || c == '\\')) out += '\\';
    out += static_cast<unsigned char>(c) < 0x20 || c == 0x7F ? '?' : c;
  }
  if (n < s.size()) out += "…";
  return quoted ? out + "\"" : out;
}

namespace {

std::string show(const toml::node& v) {
  if (const auto* s = v.as_string()) return shownInMessage(s->get(), true);
  if (const auto* i = v.as_integer()) return std::to_string(i->get());
  if (const auto* f = v.as_floating_point()) return compactNumber(f->get());
  if (const auto* b = v.as_boolean()) return b->get() ? "true" : "false";
  if (v.is_table()) return "{…}";
  if (v.is_array()) return "[…]";
  return "(a date or time)";
}

// A value computed for a key rather than written: six significant digits.
std::string approximate(double x) { return formatApprox(x, 6); }

std::string_view modelName(InstrumentModel m) {
  return m == InstrumentModel::string ? "string" : "plate";
}

// "plate model only; this preset's model is \"string\"": a key or table of the other model.
std::string otherModelOnly(InstrumentModel model) {
  const InstrumentModel other =
      model == InstrumentModel::string ? InstrumentModel::plate : InstrumentModel::string;
  return std::string(modelName(other)) + " model only; this preset's model is \"" +
         std::string(modelName(model)) + "\"";
}

bool inChoices(std::string_view choices, std::string_view word) {
  while (true) {
    const size_t bar = choices.find('|');
    if (choices.substr(0, bar) == word) return true;
    if (bar == std::string_view::npos) return false;
    choices.remove_prefix(bar + 1);
  }
}

// "\"string\" or \"plate\"", "one of 1, 2, 4, 8, 16, 32, 64".
std::string listChoices(std::string_view choices, bool quoted) {
  std::vector<std::string> words;
  for (size_t start = 0; start <= choices.size();) {
    const size_t bar = std::min(choices.find('|', start), choices.size());
    const std::string word(choices.substr(start, bar - start));
    words.push_back(quoted ? "\"" + word + "\"" : word);
    start = bar + 1;
  }
  if (words.size() == 2) return words[0] + " or " + words[1];
  std::string out = "one of ";
  for (size_t i = 0; i < words.size(); ++i) out += (i > 0 ? ", " : "") + words[i];
  return out;
}

// "0.01 … inf", and the other parameter that bounds it: a value refused on its own range is then
// not sent on to the other's (loss.t60_high_s = −1 read "expected 0.01 … inf", yet at most
// loss.t60_low_s holds too).
std::string rangeText(const Parameter& p) {
  std::string text = compactNumber(p.min) + " … " + compactNumber(p.max);
  if (!p.minOf.empty()) text += ", and at least " + std::string(p.minOf);
  if (!p.maxOf.empty()) text += ", and at most " + std::string(p.maxOf);
  return text;
}

char lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

// Edits (insert, delete, substitute, swap two neighbours) from a to b, case aside.
size_t distance(std::string_view a, std::string_view b) {
  std::vector<size_t> before(b.size() + 1), previous(b.size() + 1), row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t change = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      row[j] = std::min({previous[j] + 1, row[j - 1] + 1, previous[j - 1] + change});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
          lower(a[i - 2]) == lower(b[j - 1]))
        row[j] = std::min(row[j], before[j - 2] + 1);
    }
    std::swap(before, previous);
    std::swap(previous, row);
  }
  return previous[b.size()];
}

std::string_view leaf(std::string_view name) { return name.substr(name.rfind('.') + 1); }

// "; did you mean X?" for the candidate a slip away from `name` (a few edits, or the same key in
// another section), or nothing.
std::string suggestion(std::string_view name, const std::vector<std::string_view>& candidates,
                       std::string_view before = "", std::string_view after = "") {
  if (name.size() > kMaxSuggested) return "";
  const size_t limit = std::clamp<size_t>(name.size() / 3, 1, 3);
  std::string_view best;
  size_t bestDistance = limit + 1;
  for (std::string_view c : candidates) {
    size_t d = distance(name, c);
    if (d > 0 && distance(leaf(name), leaf(c)) == 0) d = std::min<size_t>(d, 1);
    if (d < bestDistance) best = c, bestDistance = d;
  }
  if (best.empty()) return "";
  return "; did you mean " + std::string(before) + std::string(best) + std::string(after) + "?";
}

// toml++ 3.3 reaches __builtin_unreachable() — undefined behaviour — when it asks whether some
// non-ASCII characters are whitespace (marzer/tomlplusplus issues 190 and 295). TOML allows
// non-ASCII text only in comments and strings, so this finds the first character elsewhere, or
// where toml++ asks the same question inside a multi-line basic string (right after a backslash,
// or first on a line after a line-ending one), before toml++ reads the text.
struct Unsafe {
  Place place;
  const char* what;
};

std::optional<Unsafe> unsafeForToml(std::string_view text) {
  enum class In { plain, comment, basic, literal, multiBasic, multiLiteral } in = In::plain;
  auto byte = [&](size_t i) { return i < text.size() ? static_cast<unsigned char>(text[i]) : 0; };
  auto blank = [](unsigned char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  // The length of the run of `quote` at i: three or more close a multi-line string (the extra
  // ones, up to two, belong to its text).
  auto run = [&](size_t i, char quote) {
    size_t n = 0;
    while (i + n < text.size() && text[i + n] == quote) ++n;
    return n;
  };
  Place at{.line = 1, .column = 0};
  size_t i = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // a byte-order mark, which toml++ skips
  // Moves to byte j, counting lines and characters (not UTF-8 continuation bytes) on the way.
  auto moveTo = [&](size_t j) {
    for (; i < j && i < text.size(); ++i) {
      if (text[i] == '\n')
        at = {.line = at.line + 1, .column = 0};
      else if ((byte(i) & 0xC0) != 0x80)
        ++at.column;
    }
  };
  while (i < text.size()) {
    const unsigned char c = byte(i);
    const size_t start = i;
    moveTo(i + 1);
    const Place here = at;
    switch (in) {
      case In::plain:
        if (c >= 0x80) return Unsafe{here, "a non-ASCII character outside a string or comment"};
        if (c == '#') in = In::comment;
        if (c == '"' || c == '\'') {
          const size_t n = run(start, static_cast<char>(c));
          if (n >= 3) {
            in = c == '"' ? In::multiBasic : In::multiLiteral;
            moveTo(start + 3);
          } else if (n == 2) {
            moveTo(start + 2);  // an empty string
          } else {
            in = c == '"' ? In::basic : In::literal;
          }
        }
        break;
      case In::comment:
        if (c == '\n') in = In::plain;
        break;
      case In::basic:
        if (c == '\\') moveTo(start + 2);
        if (c == '"' || c == '\n') in = In::plain;
        break;
      case In::literal:
        if (c == '\'' || c == '\n') in = In::plain;
        break;
      case In::multiBasic:
        if (c == '\\') {
          size_t j = start + 1;
          if (byte(j) >= 0x80) return Unsafe{here, "a non-ASCII character after a backslash"};
          if (blank(byte(j))) {
            while (blank(byte(j))) ++j;
            if (byte(j) >= 0x80)
              return Unsafe{here, "a non-ASCII character first after a line-ending backslash"};
          } else {
            ++j;  // an escaped character: \" does not end the string
          }
          moveTo(j);
        } else if (c == '"' && run(start, '"') >= 3) {
          moveTo(start + std::min<size_t>(run(start, '"'), 5));
          in = In::plain;
        }
        break;
      case In::multiLiteral:
        if (c == '\'' && run(start, '\'') >= 3) {
          moveTo(start + std::min<size_t>(run(start, '\''), 5));
          in = In::plain;
        }
        break;
    }
  }
  return std::nullopt;
}

// A --set VALUE as the one value of the table's key "x": what `x = VALUE` in a file would be; or
// the text itself as a string where that is not one value (a bare word: longitudinal, C4) or where
// `p` wants a word (a choice or text) and VALUE reads as another type — so that the row's own check
// says what is valid, and nothing VALUE holds can add a key.
toml::table overrideValue(const Parameter* p, const std::string& text) {
  const std::string document = "x = " + text;
  const bool wantsWord = p && (p->type == ParameterType::choice || p->type == ParameterType::text);
  if (!unsafeForToml(document)) try {
      toml::table parsed = toml::parse(document);
      const toml::node* x = parsed.get("x");
      if (parsed.size() == 1 && x && (x->is_string() || !wantsWord)) return parsed;
    } catch (const toml::parse_error&) {
    }
  return toml::table{{"x", text}};
}

// The sections of the table ("string", "hammer", …), not counting "key" (the anchors).
std::vector<std::string_view> sections() {
  std::vector<std::string_view> out;
  for (const Parameter& p : parameters()) {
    const std::string_view s = sectionOf(p.name);
    if (!s.empty() && s != "key" && std::find(out.begin(), out.end(), s) == out.end())
      out.push_back(s);
  }
  return out;
}

bool isSection(std::string_view name) {
  const auto all = sections();
  return std::find(all.begin(), all.end(), name) != all.end();
}

std::vector<std::string_view> keyNames(bool perKeyOnly) {
  std::vector<std::string_view> out;
  for (const Parameter& p : parameters())
    if (sectionOf(p.name) != "key" && (!perKeyOnly || p.perKey)) out.push_back(p.name);
  return out;
}

class Loader {
 public:
  explicit Loader(std::string source) : source_(std::move(source)) {}
  Instrument load(std::string_view text, const PresetOptions& options);

 private:
  void error(Place at, std::string message);
  [[noreturn]] void fail();
  void throwIfErrors() {
    if (!errors_.empty() || dropped_ > 0) fail();
  }

  void readModel(const toml::table& root);
  void readRoot(const toml::table& root);
  void readSection(std::string_view section, const toml::table& table, Place at);
  void readAnchors(const toml::node& node, Place at);
  void readAnchor(const toml::table& table, size_t ordinal);
  void readOverrides(const std::vector<PresetOverride>& overrides, const std::string& label);
  std::string said(const std::string& name, const std::string& shown, Place at) const;
  void entry(std::string name, const toml::node& value, Place at, Settings& into,
             const std::string& label);
  std::optional<Setting> convert(const Parameter& p, const toml::node& value, Place at,
                                 const std::string& label);
  void checkRequired();
  void checkAnchors();
  void checkBounds();
  void checkBound(const Parameter& p, const Parameter& other, bool upper);
  Instrument build() const;
  void checkVoices(const Instrument& instrument, double rate);
  void voiceError(std::string_view message, int note);
  std::string withOverrides(Place blamed) const;

  Blame blame(const Parameter& p, int note, bool sayNote) const;

  std::string source_;
  std::vector<std::pair<Place, std::string>> errors_;
  size_t dropped_ = 0;
  PresetValues values_;
  std::set<std::string> seen_;          // names the file sets, valid or not
  std::set<std::string_view> invalid_;  // parameters set somewhere to an invalid value
  std::set<std::pair<Place, std::string_view>> voiceReported_;  // (setting, parameter)
  std::vector<std::string> overrides_;  // "--set NAME=VALUE" for each, as messages show it
};

void Loader::error(Place at, std::string message) {
  if (errors_.size() >= kMaxKept) {
    ++dropped_;
    return;
  }
  errors_.emplace_back(at, std::move(message));
}

void Loader::fail() {
  std::stable_sort(errors_.begin(), errors_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  const size_t total = errors_.size() + dropped_;
  const size_t shown = total > kMaxLines ? kMaxLines - 1 : total;
  std::vector<std::string> lines;
  for (size_t i = 0; i < shown; ++i) {
    const Place& at = errors_[i].first;
    std::string line = source_;
    if (at.set == 0)  // a --set's line names it instead
      line.append(":")
          .append(std::to_string(at.line))
          .append(":")
          .append(std::to_string(at.column));
    lines.push_back(line.append(": ").append(errors_[i].second));
  }
  if (shown < total)
    lines.push_back(source_ + ": … and " + std::to_string(total - shown) + " more errors");
  throw PresetError(std::move(lines));
}

Instrument Loader::load(std::string_view text, const PresetOptions& options) {
  if (text.size() > kMaxBytes)
    throw PresetError({source_ + ": " + std::to_string(text.size()) +
                       " bytes: larger than the 1 MiB a preset may be"});
  if (const auto unsafe = unsafeForToml(text)) {
    error(unsafe->place, std::string("syntax error: ") + unsafe->what);
    fail();
  }
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(source_));
  } catch (const toml::parse_error& e) {
    error(placeOf(e.source()), "syntax error: " + std::string(e.description()));
    fail();
  }
  readModel(root);
  readRoot(root);
  checkAnchors();  // the file's own: a narrower range from --set keeps the anchors beyond it
  readOverrides(options.overrides, options.overrideLabel);
  checkRequired();
  checkBounds();
  throwIfErrors();
  Instrument instrument = build();
  if (options.checkVoices) checkVoices(instrument, options.checkRate);
  throwIfErrors();
  return instrument;
}

// The model decides which keys are valid, so it is read first; a bad one is reported with the
// other keys.
void Loader::readModel(const toml::table& root) {
  if (const toml::node* model = root.get("model"); model && model->is_string()) {
    if (model->as_string()->get() == "string") values_.model = InstrumentModel::string;
    if (model->as_string()->get() == "plate") values_.model = InstrumentModel::plate;
  }
}

void Loader::readRoot(const toml::table& root) {
  for (auto&& [key, value] : root) {
    const std::string name(key.str());
    const Place at = placeOf(key.source());
    if (name == "key")
      readAnchors(value, at);
    else if (!isSection(name))
      entry(name, value, at, values_.settings, "");
    else if (const toml::table* table = value.as_table())
      readSection(name, *table, at);
    else
      error(at, name + " = " + show(value) + ": expected a table, [" + name + "]");
  }
}

void Loader::readSection(std::string_view section, const toml::table& table, Place at) {
  if (values_.model) {
    const auto all = parameters();
    const bool any = std::any_of(all.begin(), all.end(), [&](const Parameter& p) {
      return sectionOf(p.name) == section && appliesTo(p, *values_.model);
    });
    if (!any) {
      error(at, "[" + std::string(section) + "]: " + otherModelOnly(*values_.model));
      return;
    }
  }
  for (auto&& [key, value] : table)
    entry(std::string(section) + "." + std::string(key.str()), value, placeOf(key.source()),
          values_.settings, "");
}

void Loader::readAnchors(const toml::node& node, Place at) {
  if (values_.model == InstrumentModel::plate) {
    error(at, "[[key]]: string model only; this preset's model is \"plate\"");
    return;
  }
  const toml::array* list = node.as_array();
  if (!list || !list->is_array_of_tables()) {
    error(at, "key = " + show(node) + ": expected [[key]] anchor tables");
    return;
  }
  if (list->size() > kMaxAnchors)
    error(at, "[[key]]: " + std::to_string(list->size()) + " anchor tables; at most " +
                  std::to_string(kMaxAnchors));
  for (size_t i = 0; i < std::min(list->size(), kMaxAnchors); ++i)
    readAnchor(*(*list)[i].as_table(), i + 1);
  std::stable_sort(values_.anchors.begin(), values_.anchors.end(),
                   [](const Anchor& a, const Anchor& b) { return a.note < b.note; });
}

void Loader::readAnchor(const toml::table& table, size_t ordinal) {
  Anchor anchor;
  std::string label = "key[" + std::to_string(ordinal) + "]";
  bool valid = false;
  for (auto&& [key, value] : table) {
    if (key.str() != "note") continue;
    anchor.place = placeOf(key.source());
    if (auto note = convert(*findParameter("key.note"), value, anchor.place, label + ".note")) {
      anchor.note = static_cast<int>(note->number);
      anchor.shown = note->shown;
      label = "key[" + noteName(anchor.note) + "]";
      valid = true;
      for (const Anchor& other : values_.anchors)
        if (other.note == anchor.note) {
          error(anchor.place, label + ".note = " + anchor.shown + ": duplicate anchor; " +
                                  noteName(anchor.note) + " is already an anchor at line " +
                                  std::to_string(other.place.line));
          valid = false;
        }
    }
  }
  if (!table.contains("note"))
    error(placeOf(table.source()),
          label + ": missing note; each [[key]] table needs note = \"C4\" (or a MIDI number)");
  for (auto&& [key, value] : table) {
    const std::string name(key.str());
    const Place at = placeOf(key.source());
    if (name == "note") continue;
    if (const toml::table* section = value.as_table(); section && isSection(name)) {
      for (auto&& [subkey, subvalue] : *section)
        entry(name + "." + std::string(subkey.str()), subvalue, placeOf(subkey.source()),
              anchor.values, label);
    } else {
      entry(name, value, at, anchor.values, label);
    }
  }
  if (valid) values_.anchors.push_back(std::move(anchor));
}

// Each --set after the file, as a key of the file: a valid one replaces the file's value, and a
// per-key one the anchors' values too, so that it holds at every key.
void Loader::readOverrides(const std::vector<PresetOverride>& overrides, const std::string& label) {
  for (const PresetOverride& o : overrides) {
    overrides_.push_back(label + shownInMessage(o.name, false) + "=" +
                         shownInMessage(o.value, false));
    const Place at{.set = static_cast<int>(overrides_.size())};
    if (o.name == "model") {
      error(at, overrides_.back() +
                    ": the model cannot be set; it decides what the file's other "
                    "keys mean (load a preset of that model instead)");
      continue;
    }
    const toml::table value = overrideValue(findParameter(o.name), o.value);
    Settings valid;
    entry(o.name, *value.get("x"), at, valid, "");
    for (auto& [name, setting] : valid) {
      values_.settings[name] = std::move(setting);
      for (Anchor& a : values_.anchors) a.values.erase(name);
    }
  }
}

// How a message names a value: "hammer.mass_kg = 0.1" from the file, or its "--set NAME=VALUE".
std::string Loader::said(const std::string& name, const std::string& shown, Place at) const {
  return at.set > 0 ? overrides_[static_cast<size_t>(at.set) - 1] : name + " = " + shown;
}

void Loader::entry(std::string name, const toml::node& value, Place at, Settings& into,
                   const std::string& label) {
  const std::string shownName = (label.empty() ? "" : label + ".") + shownInMessage(name, false);
  const std::string head = said(shownName, show(value), at);
  const Parameter* any = findParameter(name);
  if (!any || sectionOf(name) == "key") {
    if (value.is_table() && at.set == 0) {
      std::vector<std::string_view> tables = sections();
      tables.push_back("key");
      error(at, "[" + shownName + "]: unknown table" + suggestion(name, tables, "[", "]"));
    } else {
      error(at, head + ": unknown key" + suggestion(name, keyNames(!label.empty())));
    }
    return;
  }
  seen_.insert(name);
  const Parameter* p = values_.model ? findParameter(name, *values_.model) : any;
  if (!p) {
    error(at, head + ": " + otherModelOnly(*values_.model));
    return;
  }
  if (!label.empty() && !p->perKey) {
    const std::string_view section = sectionOf(p->name);
    error(at, head + ": not per-key; set it " +
                  (section.empty() ? std::string("at the top level")
                                   : "in [" + std::string(section) + "]"));
    return;
  }
  if (auto s = convert(*p, value, at, shownName))
    into[p->name] = std::move(*s);
  else
    invalid_.insert(p->name);
}

std::optional<Setting> Loader::convert(const Parameter& p, const toml::node& value, Place at,
                                       const std::string& label) {
  Setting s{.place = at, .shown = show(value)};
  auto refuse = [&](const std::string& what) {
    error(at, said(label, s.shown, at) + ": " + what);
    return std::nullopt;
  };
  switch (p.type) {
    case ParameterType::real: {
      double x = 0.0;
      if (const auto* i = value.as_integer())
        x = static_cast<double>(i->get());
      else if (const auto* f = value.as_floating_point())
        x = f->get();
      else
        return refuse("expected a number");
      if (std::isnan(x) || (std::isinf(x) && (x > 0 ? p.max : -p.min) != INFINITY))
        return refuse("not a finite number");
      if (x < p.min || x > p.max) return refuse("out of range; expected " + rangeText(p));
      s.number = x;
      return s;
    }
    case ParameterType::integer: {
      const auto* i = value.as_integer();
      if (!i) return refuse("expected an integer");
      const std::int64_t n = i->get();
      if (!p.choices.empty() && !inChoices(p.choices, std::to_string(n)))
        return refuse("expected " + listChoices(p.choices, false));
      if (n < p.min || n > p.max) return refuse("out of range; expected " + rangeText(p));
      s.number = static_cast<double>(n);
      return s;
    }
    case ParameterType::choice: {
      const auto* w = value.as_string();
      if (!w || !inChoices(p.choices, w->get()))
        return refuse("expected " + listChoices(p.choices, true));
      s.word = w->get();
      return s;
    }
    case ParameterType::boolean: {
      const auto* b = value.as_boolean();
      if (!b) return refuse("expected true or false");
      s.number = b->get() ? 1.0 : 0.0;
      return s;
    }
    case ParameterType::note: {
      std::optional<int> n;
      if (const auto* i = value.as_integer()) {
        if (i->get() >= 0 && i->get() <= 127) n = static_cast<int>(i->get());
      } else if (const auto* w = value.as_string()) {
        n = parseNoteName(w->get());
      }
      if (!n) return refuse("expected a MIDI note 0 … 127 or a name like \"C4\"");
      s.number = *n;
      return s;
    }
    case ParameterType::text: {
      const auto* w = value.as_string();
      if (!w) return refuse("expected text in quotes");
      if (w->get().size() > kMaxText)
        return refuse("longer than " + std::to_string(kMaxText) + " bytes");
      s.word = w->get();
      return s;
    }
  }
  return std::nullopt;
}

void Loader::checkRequired() {
  for (const Parameter& p : parameters())
    if (p.defaultKind == DefaultKind::required && sectionOf(p.name) != "key" &&
        !seen_.count(std::string(p.name)) && (!values_.model || appliesTo(p, *values_.model)))
      error({}, std::string(p.name) + ": missing; expected " +
                    (p.type == ParameterType::choice
                         ? listChoices(p.choices, true)
                         : std::string("a MIDI note 0 … 127 or a name like \"C4\"")));
}

void Loader::checkAnchors() {
  const Setting* lowest = values_.setting("lowest_note");
  const Setting* highest = values_.setting("highest_note");
  if (!lowest || !highest) return;
  const int lo = static_cast<int>(lowest->number), hi = static_cast<int>(highest->number);
  for (const Anchor& a : values_.anchors)
    if (a.note < lo || a.note > hi)
      error(a.place, "key[" + noteName(a.note) + "].note = " + a.shown +
                         ": outside lowest_note … highest_note, " + noteName(lo) + " … " +
                         noteName(hi));
}

// The bounds one parameter puts on another (highest_note >= lowest_note, t60_high_s <=
// t60_low_s, …), where both values are valid.
void Loader::checkBounds() {
  if (!values_.setting("lowest_note") || !values_.setting("highest_note")) return;
  for (const Parameter& p : parameters()) {
    if (p.minOf.empty() && p.maxOf.empty()) continue;
    if (values_.model ? !appliesTo(p, *values_.model) : p.model != ParameterModel::both) continue;
    const bool upper = !p.maxOf.empty();
    const Parameter& other = values_.row(upper ? p.maxOf : p.minOf);
    // A derived default has no number to compare: the voice checks what it derives.
    auto unsetDerived = [&](const Parameter& q) {
      return q.defaultKind == DefaultKind::derived && !values_.setting(q.name) &&
             !values_.anchored(q);
    };
    if (unsetDerived(p) || unsetDerived(other)) continue;
    if (!invalid_.count(p.name) && !invalid_.count(other.name)) checkBound(p, other, upper);
  }
}

void Loader::checkBound(const Parameter& p, const Parameter& other, bool upper) {
  // Without anchors for either, both hold at every key: one comparison says all.
  const bool perKey = values_.anchored(p) || values_.anchored(other);
  const int lo = static_cast<int>(values_.number("lowest_note"));
  const int hi = perKey ? static_cast<int>(values_.number("highest_note")) : lo;
  // The one set in the file is blamed; with both set, the bounded one — unless only the other was
  // given by --set, which is then what changed.
  auto bySet = [&](const Parameter& q) {
    const Setting* s = values_.setting(q.name);
    return s && s->place.set > 0;
  };
  const bool blameP =
      (bySet(p) || !bySet(other)) && (values_.setting(p.name) || values_.anchored(p) ||
                                      (!values_.setting(other.name) && !values_.anchored(other)));
  // The anchors' own notes first, so that an anchor's value is reported at its note.
  std::vector<int> notes;
  if (perKey)
    for (const Anchor& a : values_.anchors)
      if (a.values.count(p.name) || a.values.count(other.name)) notes.push_back(a.note);
  for (int note = lo; note <= hi; ++note) notes.push_back(note);
  std::set<Place> reported;
  for (int note : notes) {
    const double x = perKey ? values_.atKey(p, note) : values_.number(p.name);
    const double y = perKey ? values_.atKey(other, note) : values_.number(other.name);
    if (upper ? x <= y : x >= y) continue;
    const Blame b = blame(blameP ? p : other, note, false);
    if (!reported.insert(b.place).second) continue;
    const std::string at = perKey ? " at " + noteName(note) : "";
    const std::string bound =
        approximate(blameP ? y : x) + " (" + std::string(blameP ? other.name : p.name) + at + ")";
    std::string expected;
    if (blameP)
      expected =
          upper ? compactNumber(p.min) + " … " + bound : bound + " … " + compactNumber(p.max);
    else
      expected = (upper ? "at least " : "at most ") + bound;
    error(b.place, b.text + ": out of range; expected " + expected);
  }
}

// The setting behind p's value at `note`: the nearest anchor that sets it, the section's value,
// or the default (at line 1).
Blame Loader::blame(const Parameter& p, int note, bool sayNote) const {
  const Anchor* nearest = nullptr;
  for (const Anchor& a : values_.anchors)
    if (a.values.count(p.name) &&
        (!nearest || std::abs(a.note - note) < std::abs(nearest->note - note)))
      nearest = &a;
  const std::string at = " at " + noteName(note);
  if (nearest && nearest->note == note)
    return {nearest->values.at(p.name).place, "key[" + noteName(note) + "]." + std::string(p.name) +
                                                  " = " + nearest->values.at(p.name).shown};
  if (nearest)
    return {nearest->values.at(p.name).place,
            std::string(p.name) + " = " + approximate(values_.atKey(p, note)) + at};
  const Setting* s = values_.setting(p.name);
  const std::string value =
      s                                 ? s->shown
      : p.type == ParameterType::choice ? "\"" + values_.word(p.name) + "\""
      : p.type == ParameterType::boolean || p.defaultKind == DefaultKind::derived
          ? std::string(p.defaultText)
          : approximate(values_.number(p.name));
  const Place place = s ? s->place : Place{};
  return {place, said(std::string(p.name), value, place) + (sayNote ? at : "")};
}

Instrument Loader::build() const {
  Instrument instrument;
  instrument.source = source_;
  instrument.name = values_.setting("name") ? values_.word("name")
                                            : std::filesystem::path(source_).stem().string();
  instrument.model = *values_.model;
  instrument.lowestNote = static_cast<int>(values_.number("lowest_note"));
  instrument.highestNote = static_cast<int>(values_.number("highest_note"));
  instrument.polyphony = static_cast<int>(values_.number("polyphony"));
  instrument.gainDb = values_.number("gain_dB");
  instrument.panSpread = values_.number("pan_spread");
  if (*values_.model == InstrumentModel::plate)
    buildPlatePatch(values_, instrument);
  else
    buildStringKeys(values_, instrument);
  return instrument;
}

void Loader::checkVoices(const Instrument& instrument, double rate) {
  const auto refused = [this](std::string_view message, int note) { voiceError(message, note); };
  if (instrument.model == InstrumentModel::plate)
    checkPlateVoices(instrument, refused, rate);
  else
    checkStringVoices(instrument, values_, refused, rate);
}

// Points the voice's complaint at the setting behind the field it names, once per setting.
void Loader::voiceError(std::string_view message, int note) {
  const size_t colon = message.find(": ");
  const std::string_view head = message.substr(0, colon);
  const std::string_view field = head.substr(0, head.find(" = "));
  const VoiceField* found = nullptr;
  for (const VoiceField& f :
       *values_.model == InstrumentModel::string ? stringVoiceFields() : plateVoiceFields())
    if (f.field == field) found = &f;
  if (!found) {
    const Setting* edge = note == values_.number("lowest_note")    ? values_.setting("lowest_note")
                          : note == values_.number("highest_note") ? values_.setting("highest_note")
                                                                   : nullptr;
    error(edge ? edge->place : Place{}, noteName(note) + " (" + std::to_string(note) +
                                            "): " + std::string(message) + withOverrides({}));
    return;
  }
  const Blame b = blame(values_.row(found->parameter), note, true);
  if (!voiceReported_.emplace(b.place, found->parameter).second) return;
  const std::string_view rest =
      found->keep || colon == std::string_view::npos ? message : message.substr(colon + 2);
  error(b.place, b.text + ": " + std::string(rest) + withOverrides(b.place));
}

// A voice refuses what the file and the --set give together: a line that blames the file (or no
// one setting) names every --set too, since one of them may be the cause.
std::string Loader::withOverrides(Place blamed) const {
  if (blamed.set > 0 || overrides_.empty()) return "";
  std::string out;
  for (const std::string& o : overrides_) out += (out.empty() ? " (with " : ", ") + o;
  return out + ")";
}

}  // namespace

PresetError::PresetError(std::vector<std::string> messages)
    : std::runtime_error([&] {
        std::string joined;
        for (const std::string& line : messages) joined += (joined.empty() ? "" : "\n") + line;
        return joined;
      }()),
      lines(std::move(messages)) {}

std::optional<PresetOverride> parseOverride(std::string_view argument) {
  const size_t equals = argument.find('=');
  if (equals == std::string_view::npos) return std::nullopt;
  auto trim = [](std::string_view s) {
    const size_t first = s.find_first_not_of(" \t");
    if (first == std::string_view::npos) return std::string_view{};
    return s.substr(first, s.find_last_not_of(" \t") - first + 1);
  };
  PresetOverride o{std::string(trim(argument.substr(0, equals))),
                   std::string(trim(argument.substr(equals + 1)))};
  if (o.name.empty()) return std::nullopt;
  return o;
}

Instrument loadPreset(const std::filesystem::path& file, const PresetOptions& options) {
  const std::string name = file.string();
  std::error_code error;
  if (!std::filesystem::exists(file, error)) {
    // ENOENT is no error to exists(); a loop of links or a directory that may not be searched is.
    if (error) throw PresetError({name + ": cannot read: " + error.message()});
    std::error_code notLink;
    if (std::filesystem::is_symlink(file, notLink))
      throw PresetError({name + ": cannot read: a symbolic link to " +
                         std::filesystem::read_symlink(file, notLink).string() +
                         ", which does not exist"});
    throw PresetError({name + ": cannot read: no such file"});
  }
  if (!std::filesystem::is_regular_file(file, error))
    throw PresetError({name + ": cannot read: not a regular file"});
  std::ifstream in(file, std::ios::binary);
  if (!in) throw PresetError({name + ": cannot open the file: " + std::strerror(errno)});
  std::string text(kMaxBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw PresetError({name + ": cannot read the file"});
  text.resize(static_cast<size_t>(in.gcount()));
  return parsePreset(text, name, options);
}

Instrument parsePreset(std::string_view text, const std::string& sourceName,
                       const PresetOptions& options) {
  return Loader(sourceName).load(text, options);
}

}  // namespace hamiltone
