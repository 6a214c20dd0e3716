// YAML input with one-line, located errors: every message starts with "FILE:LINE: key.path:" (or
// "--set key.path=..." for command-line overrides), and keys nobody asked for are errors.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "formats/kinds.h"

namespace femb {

class YamlMap;

/// Shared bookkeeping of one document: its file name and the keys overridden by --set.
struct YamlSource {
  std::string file;
  std::set<std::string> overridden;  ///< dotted key paths set from the command line
};

/// One value in a document, with its location for error messages.
class YamlValue {
 public:
  YamlValue(YAML::Node node, std::string path, std::shared_ptr<const YamlSource> source)
      : node_(std::move(node)), path_(std::move(path)), source_(std::move(source)) {}

  double Number() const;
  double PositiveNumber() const;
  long Integer() const;
  long NonNegativeInteger() const;
  bool Bool() const;
  std::string String() const;
  /// A string that must be one of `allowed`; fails "expected a or b, got 'x'" (+ `note`).
  std::string OneOf(const std::vector<std::string>& allowed, const std::string& note = "") const;
  /// The kind this value names (formats/kinds.h); fails "unknown <what> 'x' (known: a, b, c)".
  template <Worded E>
  E Kind(const std::string& what) const {
    const std::string s = String();
    if (std::optional<E> kind = KindOf<E>(s)) return *kind;
    Fail("unknown " + what + " '" + s + "' (known: " + JoinWords(WordsOf<E>()) + ")");
  }
  /// The same with OneOf's message: "expected a, b or c, got 'x'" (+ `note`).
  template <Worded E>
  E OneOfKinds(const std::string& note = "") const {
    return *KindOf<E>(OneOf(WordsOf<E>(), note));
  }
  Eigen::Vector3d Vector3() const;
  YamlMap Map() const;
  std::vector<YamlValue> List() const;
  bool IsMap() const { return node_.IsMap(); }
  bool IsList() const { return node_.IsSequence(); }
  bool IsScalar() const { return node_.IsScalar(); }

  /// "FILE:LINE: key.path" or "--set key.path".
  std::string Where() const;
  const std::string& path() const { return path_; }
  [[noreturn]] void Fail(const std::string& message) const;

 private:
  YAML::Node node_;
  std::string path_;
  std::shared_ptr<const YamlSource> source_;
};

/// A mapping whose keys are checked: call CheckNoUnknownKeys() after asking for every key the
/// program understands; any other key is reported with its line and the list of known keys.
class YamlMap {
 public:
  YamlMap(YAML::Node node, std::string path, std::shared_ptr<const YamlSource> source);
  YamlValue Required(const std::string& key) const;
  std::optional<YamlValue> Optional(const std::string& key) const;
  /// The entries in document order (for maps keyed by user-chosen names); marks all as known.
  std::vector<std::pair<std::string, YamlValue>> Entries() const;
  void CheckNoUnknownKeys() const;
  YamlValue AsValue() const { return YamlValue(node_, path_, source_); }

 private:
  std::string Child(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  YAML::Node node_;
  std::string path_;
  std::shared_ptr<const YamlSource> source_;
  std::shared_ptr<std::set<std::string>> asked_ = std::make_shared<std::set<std::string>>();
};

/// A parsed document. Throws InputError "FILE: cannot open ..." or
/// "FILE:LINE:COL: YAML syntax error: ...".
class YamlDocument {
 public:
  static YamlDocument LoadFile(const std::string& path);
  static YamlDocument LoadString(const std::string& text, const std::string& name);
  /// Applies a command-line override "a.b.c=value" (value parsed as YAML). Throws InputError for
  /// a malformed assignment or a path through a non-mapping.
  void Set(const std::string& assignment);
  YamlMap Root() const;
  const std::string& file() const { return source_->file; }

 private:
  YAML::Node root_;
  std::shared_ptr<YamlSource> source_;
};

/// The whole text of a file; throws InputError "PATH: cannot open WHAT (...)".
std::string ReadTextFile(const std::string& path, const std::string& what);

}  // namespace femb
