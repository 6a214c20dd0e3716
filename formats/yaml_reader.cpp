#include "formats/yaml_reader.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "formats/input_error.h"

namespace femb {

std::string YamlValue::Where() const {
  // Set on the command line: the value itself, or inside a mapping or list item set whole.
  for (size_t i = 0; i <= path_.size(); ++i) {
    if ((i == path_.size() || path_[i] == '.' || path_[i] == '[') && source_->overridden.count(path_.substr(0, i))) {
      return "--set " + path_;
    }
  }
  // yaml-cpp counts lines from 0.
  std::string where = source_->file;
  if (node_.Mark().line >= 0) where += ":" + std::to_string(node_.Mark().line + 1);
  return where + (path_.empty() ? "" : ": " + path_);
}

void YamlValue::Fail(const std::string& message) const { throw InputError(Where() + ": " + message); }

double YamlValue::Number() const {
  if (!node_.IsScalar()) Fail("expected a number");
  const std::string text = node_.Scalar();
  char* end = nullptr;
  double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value)) Fail("expected a number, got '" + text + "'");
  return value;
}

double YamlValue::PositiveNumber() const {
  double value = Number();
  if (!(value > 0.0)) Fail("must be positive, got " + node_.Scalar());
  return value;
}

long YamlValue::Integer() const {
  if (!node_.IsScalar()) Fail("expected an integer");
  const std::string text = node_.Scalar();
  char* end = nullptr;
  long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0') Fail("expected an integer, got '" + text + "'");
  return value;
}

long YamlValue::NonNegativeInteger() const {
  long value = Integer();
  if (value < 0) Fail("must be zero or positive, got " + std::to_string(value));
  return value;
}

bool YamlValue::Bool() const {
  if (!node_.IsScalar()) Fail("expected true or false");
  const std::string t = node_.Scalar();
  if (t == "true" || t == "True" || t == "yes" || t == "on") return true;
  if (t == "false" || t == "False" || t == "no" || t == "off") return false;
  Fail("expected true or false, got '" + t + "'");
}

std::string YamlValue::String() const {
  if (!node_.IsScalar()) Fail("expected a string");
  return node_.Scalar();
}

std::string YamlValue::OneOf(const std::vector<std::string>& allowed, const std::string& note) const {
  const std::string s = String();
  for (const std::string& a : allowed) {
    if (s == a) return s;
  }
  std::string list;
  for (size_t i = 0; i < allowed.size(); ++i) {
    list += (i == 0 ? "" : i + 1 == allowed.size() ? " or " : ", ") + allowed[i];
  }
  Fail("expected " + list + (note.empty() ? "" : " " + note) + ", got '" + s + "'");
}

Eigen::Vector3d YamlValue::Vector3() const {
  if (!node_.IsSequence() || node_.size() != 3) Fail("expected a list of 3 numbers [x, y, z]");
  Eigen::Vector3d v;
  auto items = List();
  for (int i = 0; i < 3; ++i) v[i] = items[i].Number();
  return v;
}

YamlMap YamlValue::Map() const {
  if (!node_.IsMap()) Fail("expected a mapping of keys to values");
  return YamlMap(node_, path_, source_);
}

std::vector<YamlValue> YamlValue::List() const {
  if (!node_.IsSequence()) Fail("expected a list");
  std::vector<YamlValue> items;
  for (size_t i = 0; i < node_.size(); ++i) {
    items.emplace_back(node_[i], path_ + "[" + std::to_string(i) + "]", source_);
  }
  return items;
}

// ---------------------------------------------------------------------------------------------
YamlMap::YamlMap(YAML::Node node, std::string path, std::shared_ptr<const YamlSource> source)
    : node_(std::move(node)), path_(std::move(path)), source_(std::move(source)) {}

std::optional<YamlValue> YamlMap::Optional(const std::string& key) const {
  asked_->insert(key);
  YAML::Node child = node_[key];
  if (!child.IsDefined() || child.IsNull()) return std::nullopt;
  return YamlValue(child, Child(key), source_);
}

YamlValue YamlMap::Required(const std::string& key) const {
  auto value = Optional(key);
  if (!value) AsValue().Fail("missing required key '" + key + "'");
  return *value;
}

std::vector<std::pair<std::string, YamlValue>> YamlMap::Entries() const {
  std::vector<std::pair<std::string, YamlValue>> entries;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    std::string key = it->first.Scalar();
    asked_->insert(key);
    entries.emplace_back(key, YamlValue(it->second, Child(key), source_));
  }
  return entries;
}

void YamlMap::CheckNoUnknownKeys() const {
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string key = it->first.Scalar();
    if (asked_->count(key)) continue;
    std::string known;
    for (const auto& k : *asked_) known += (known.empty() ? "" : ", ") + k;
    YamlValue where(it->first, Child(key), source_);
    where.Fail("unknown key '" + key + "'" + (path_.empty() ? "" : " in '" + path_ + "'") + " (known keys: " + known +
               ")");
  }
}

// ---------------------------------------------------------------------------------------------
YamlDocument YamlDocument::LoadString(const std::string& text, const std::string& name) {
  YamlDocument doc;
  doc.source_ = std::make_shared<YamlSource>();
  doc.source_->file = name;
  try {
    doc.root_ = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(name + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                     ": YAML syntax error: " + e.msg);
  }
  if (!doc.root_.IsMap()) {
    throw InputError(name + ": expected a YAML mapping of keys to values at the top level");
  }
  return doc;
}

std::string ReadTextFile(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open " + what + " (does it exist and is it readable?)");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

YamlDocument YamlDocument::LoadFile(const std::string& path) { return LoadString(ReadTextFile(path, "file"), path); }

void YamlDocument::Set(const std::string& assignment) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw InputError("--set " + assignment + ": expected key.path=value");
  }
  const std::string key = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  YAML::Node value;
  try {
    value = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError("--set " + assignment + ": value is not valid YAML: " + e.msg);
  }
  // Key path: components separated by '.', each a key optionally followed by list indices
  // ("bodies[1].options.modal_damping"). Steps: (key, -1) or ("", index).
  std::vector<std::pair<std::string, long>> steps;
  std::stringstream ss(key);
  for (std::string part; std::getline(ss, part, '.');) {
    const size_t bracket = part.find('[');
    const std::string name = part.substr(0, bracket);
    if (name.empty()) throw InputError("--set " + assignment + ": empty key in key path");
    steps.emplace_back(name, -1);
    for (size_t at = bracket; at != std::string::npos;) {
      const size_t close = part.find(']', at);
      const std::string digits = close == std::string::npos ? "" : part.substr(at + 1, close - at - 1);
      if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos ||
          (close + 1 < part.size() && part[close + 1] != '[')) {
        throw InputError("--set " + assignment + ": malformed list index in '" + part + "' (expected key[N])");
      }
      steps.emplace_back("", std::stol(digits));
      at = close + 1 < part.size() ? close + 1 : std::string::npos;
    }
  }
  // yaml-cpp nodes are handles: walk down by reassigning node references.
  std::vector<YAML::Node> chain{root_};
  std::string walked;
  for (size_t i = 0; i + 1 < steps.size(); ++i) {
    const auto& [name, index] = steps[i];
    if (index >= 0) {
      const YAML::Node list = chain.back();
      if (!list.IsSequence() || index >= long(list.size())) {
        throw InputError("--set " + assignment + ": '" + walked + "' has no item " + std::to_string(index) + " in " +
                         file() +
                         (list.IsSequence() ? " (it has " + std::to_string(list.size()) + ")" : " (not a list)"));
      }
      walked += "[" + std::to_string(index) + "]";
      chain.push_back(list[std::size_t(index)]);
      continue;
    }
    // A key below a list item or a scalar (found by fuzzing: 'points.R[0].element' on a
    // coordinate list made yaml-cpp throw BadSubscript).
    if (chain.back().IsDefined() && !chain.back().IsNull() && !chain.back().IsMap()) {
      throw InputError("--set " + assignment + ": '" + walked + "' is not a mapping in " + file() +
                       " (it has no key '" + name + "')");
    }
    walked += (walked.empty() ? "" : ".") + name;
    YAML::Node next = chain.back()[name];
    const bool indexed = steps[i + 1].second >= 0;
    if (next.IsDefined() && !next.IsNull() && !indexed && !next.IsMap()) {
      throw InputError("--set " + assignment + ": '" + name + "' is not a mapping in " + file());
    }
    if (!next.IsDefined() || next.IsNull()) {
      if (indexed) throw InputError("--set " + assignment + ": '" + walked + "' is not a list in " + file());
      chain.back()[name] = YAML::Node(YAML::NodeType::Map);
      next = chain.back()[name];
    }
    chain.push_back(next);
  }
  const long last = steps.back().second;
  if (last >= 0) {
    // A whole list item: replaced, or appended at the index one past the last.
    YAML::Node list = chain.back();
    if (!list.IsSequence()) throw InputError("--set " + assignment + ": '" + walked + "' is not a list in " + file());
    if (last > long(list.size())) {
      throw InputError("--set " + assignment + ": '" + walked + "' has no item " + std::to_string(last) + " in " +
                       file() + " (it has " + std::to_string(list.size()) + "; [" + std::to_string(list.size()) +
                       "] appends one)");
    }
    if (last == long(list.size())) {
      list.push_back(value);
    } else {
      list[std::size_t(last)] = value;
    }
    source_->overridden.insert(key);
    return;
  }
  if (!chain.back().IsMap() && chain.back().IsDefined() && !chain.back().IsNull()) {
    throw InputError("--set " + assignment + ": '" + walked + "' is not a mapping in " + file());
  }
  chain.back()[steps.back().first] = value;
  source_->overridden.insert(key);
}

YamlMap YamlDocument::Root() const { return YamlMap(root_, "", source_); }

}  // namespace femb
