#include "formats/yaml_reader.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "formats/input_error.h"

namespace femb {

std::string YamlValue::Where() const {
  if (source_->overridden.count(path_)) return "--set " + path_;
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
    where.Fail("unknown key '" + key + "'" + (path_.empty() ? "" : " in '" + path_ + "'") +
               " (known keys: " + known + ")");
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
    throw InputError(name + ":" + std::to_string(e.mark.line + 1) + ":" +
                     std::to_string(e.mark.column + 1) + ": YAML syntax error: " + e.msg);
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
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string part; std::getline(ss, part, '.');) {
    if (part.empty()) throw InputError("--set " + assignment + ": empty component in key path");
    parts.push_back(part);
  }
  // yaml-cpp nodes are handles: walk down by reassigning node references.
  std::vector<YAML::Node> chain{root_};
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next = chain.back()[parts[i]];
    if (next.IsDefined() && !next.IsNull() && !next.IsMap()) {
      throw InputError("--set " + assignment + ": '" + parts[i] + "' is not a mapping in " + file());
    }
    if (!next.IsDefined() || next.IsNull()) {
      chain.back()[parts[i]] = YAML::Node(YAML::NodeType::Map);
      next = chain.back()[parts[i]];
    }
    chain.push_back(next);
  }
  chain.back()[parts.back()] = value;
  source_->overridden.insert(key);
}

YamlMap YamlDocument::Root() const { return YamlMap(root_, "", source_); }

}  // namespace femb
