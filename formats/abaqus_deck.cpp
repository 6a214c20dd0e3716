// Abaqus input decks (formats/abaqus_deck.h).
#include "formats/abaqus_deck.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <unordered_map>

#include "formats/input_error.h"
#include "formats/text_lines.h"

namespace femb {
namespace {

// "*Element, type=C3D10, elset=ALL": the keyword in upper case with single spaces, and the
// parameters (upper-case keys; values as written, quotes removed).
struct Keyword {
  std::string name;
  std::map<std::string, std::string> parameters;
  bool Has(const std::string& key) const { return parameters.count(key) > 0; }
  std::string Get(const std::string& key) const {
    auto it = parameters.find(key);
    return it == parameters.end() ? std::string() : it->second;
  }
};

Keyword ParseKeyword(const std::string& line) {
  Keyword k;
  const std::vector<std::string_view> f = CommaFields(std::string_view(line).substr(1));
  for (char c : UpperCase(f[0])) {
    if (c == ' ' && (k.name.empty() || k.name.back() == ' ')) continue;
    k.name.push_back(c);
  }
  for (size_t i = 1; i < f.size(); ++i) {
    if (f[i].empty()) continue;
    const size_t eq = f[i].find('=');
    std::string key = UpperCase(f[i].substr(0, eq));
    key.erase(std::remove(key.begin(), key.end(), ' '), key.end());
    std::string value = eq == std::string_view::npos ? std::string() : std::string(f[i].substr(eq + 1));
    while (!value.empty() && value.front() == ' ') value.erase(value.begin());
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') value = value.substr(1, value.size() - 2);
    k.parameters[key] = value;
  }
  return k;
}

// Nodes per element for the types whose data lines may run over several lines without a
// trailing comma; others end at a line without one.
int KnownNodeCount(const std::string& type) {
  static const std::vector<std::pair<std::string, int>> kCounts = {
      {"C3D4", 4}, {"C3D10", 10}, {"C3D8", 8}, {"C3D20", 20}, {"C3D6", 6}, {"C3D15", 15}, {"S3", 3},     {"S4", 4},
      {"S8", 8},   {"STRI65", 6}, {"SC8", 8},  {"SC6", 6},    {"M3D3", 3}, {"M3D4", 4},   {"M3D6", 6},   {"M3D8", 8},
      {"B31", 2},  {"B32", 3},    {"B33", 2},  {"T3D2", 2},   {"T3D3", 3}, {"MASS", 1},   {"ROTARYI", 1}};
  int best = 0;
  size_t best_length = 0;
  for (const auto& [prefix, count] : kCounts)
    if (type.rfind(prefix, 0) == 0 && prefix.size() > best_length) {
      best = count;
      best_length = prefix.size();
    }
  return best;
}

// A part as the deck defines it, in part coordinates, with its sets by label.
struct Part {
  std::string name;  // upper case
  std::vector<long> labels;
  std::vector<Eigen::Vector3d> x;
  std::vector<AbaqusElement> elements;
  std::vector<long> element_lines;
  std::map<std::string, std::set<long>> nsets, elsets;
};

struct Instance {
  std::string name, part;  // name as written; part upper case
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  int placement_lines = 0;
  std::map<std::string, std::set<long>> nsets, elsets;  // assembly sets on this instance
};

class DeckParser {
 public:
  explicit DeckParser(const std::string& path) : r_(path, "Abaqus deck") {}

  AbaqusDeck Parse();

 private:
  enum class Data { kNone, kNode, kElement, kNset, kElset, kInstance };

  void OnKeyword(const Keyword& k);
  void OnData(const std::string& line);
  void AddSetEntries(const std::vector<std::string_view>& f);
  Part& Current() { return parts_[size_t(part_ >= 0 ? part_ : 0)]; }
  std::map<std::string, std::set<long>>& SetsOf(Instance* instance, Part& part, bool node_set) {
    if (instance) return node_set ? instance->nsets : instance->elsets;
    return node_set ? part.nsets : part.elsets;
  }
  AbaqusMesh Place(const Instance& instance) const;
  // The part named `name` (upper case; "" is a flat deck's top level), the last one defined; null
  // when the deck defines none of that name.
  const Part* PartNamed(const std::string& name) const {
    for (auto p = parts_.rbegin(); p != parts_.rend(); ++p)
      if (p->name == name) return &*p;
    return nullptr;
  }

  LineReader r_;
  std::vector<Part> parts_{Part{}};  // parts_[0]: the top level of a flat deck
  std::vector<Instance> instances_;
  int part_ = -1;  // inside *Part: its index
  bool in_assembly_ = false;
  int in_instance_ = -1;  // inside *Instance: its index
  Data data_ = Data::kNone;
  std::string element_type_, set_name_, set_instance_;
  std::string element_set_;  // *Element, elset=
  std::string node_set_;     // *Node, nset=
  // Set names are matched in upper case; the sets keep the spelling of their first definition.
  std::map<std::string, std::string> spelling_;
  std::string Spell(const std::string& written) {
    const std::string upper = UpperCase(written);
    if (!upper.empty()) spelling_.emplace(upper, written);
    return upper;
  }
  bool generate_ = false;
  long keyword_line_ = 0;
  std::vector<std::string> pending_;  // an element's fields over continuation lines
  long assembly_nodes_ = 0;
};

void DeckParser::OnKeyword(const Keyword& k) {
  data_ = Data::kNone;
  keyword_line_ = r_.number();
  const std::string& n = k.name;
  if (n == "INCLUDE") r_.Fail("*Include is not read: put the included file's lines into the deck");
  if (n == "PART") {
    if (!k.Has("NAME") || k.Get("NAME").empty()) r_.Fail("*Part without name=");
    parts_.push_back(Part{});
    parts_.back().name = UpperCase(k.Get("NAME"));
    part_ = int(parts_.size() - 1);
  } else if (n == "END PART") {
    part_ = -1;
  } else if (n == "ASSEMBLY") {
    in_assembly_ = true;
  } else if (n == "END ASSEMBLY") {
    in_assembly_ = false;
  } else if (n == "INSTANCE") {
    if (!k.Has("PART") || k.Get("PART").empty())
      r_.Fail("*Instance without part= (an instance that defines its own mesh is not read)");
    Instance instance;
    instance.name = k.Get("NAME");
    instance.part = UpperCase(k.Get("PART"));
    instances_.push_back(instance);
    in_instance_ = int(instances_.size() - 1);
    data_ = Data::kInstance;
  } else if (n == "END INSTANCE") {
    in_instance_ = -1;
  } else if (n == "NODE") {
    if (in_instance_ >= 0) r_.Fail("*Node inside *Instance: an instance that defines its own mesh is not read");
    data_ = Data::kNode;
    node_set_ = Spell(k.Get("NSET"));
  } else if (n == "ELEMENT") {
    if (!k.Has("TYPE") || k.Get("TYPE").empty()) r_.Fail("*Element without type=");
    data_ = Data::kElement;
    element_type_ = UpperCase(k.Get("TYPE"));
    element_set_ = Spell(k.Get("ELSET"));
  } else if (n == "NSET" || n == "ELSET") {
    const std::string key = n == "NSET" ? "NSET" : "ELSET";
    if (!k.Has(key) || k.Get(key).empty())
      r_.Fail("*" + std::string(n == "NSET" ? "Nset" : "Elset") + " without " + (n == "NSET" ? "nset=" : "elset="));
    data_ = n == "NSET" ? Data::kNset : Data::kElset;
    set_name_ = Spell(k.Get(key));
    set_instance_ = UpperCase(k.Get("INSTANCE"));
    generate_ = k.Has("GENERATE");
  }
}

// Labels, set names or GENERATE ranges of a *Nset / *Elset data line into the set named by the
// keyword (on the part, or on the instance for the assembly's sets).
void DeckParser::AddSetEntries(const std::vector<std::string_view>& f) {
  const bool node_set = data_ == Data::kNset;
  auto instance_named = [&](const std::string& name) -> Instance* {
    for (Instance& i : instances_)
      if (UpperCase(i.name) == name) return &i;
    r_.Fail("no instance named '" + name + "' (defined before this line)");
  };
  Instance* scope = nullptr;
  if (in_assembly_ && in_instance_ < 0) {
    if (!set_instance_.empty()) scope = instance_named(set_instance_);
  }
  auto target = [&](Instance* instance) -> std::set<long>& {
    if (instance) return (node_set ? instance->nsets : instance->elsets)[set_name_];
    return SetsOf(nullptr, Current(), node_set)[set_name_];
  };
  if (generate_) {
    if (f.size() < 2 || f.size() > 3) r_.Fail("GENERATE expects 'first, last[, step]'");
    const long first = IntegerField(r_, f[0]), last = IntegerField(r_, f[1]);
    const long step = f.size() == 3 && !f[2].empty() ? IntegerField(r_, f[2]) : 1;
    if (step <= 0 || last < first) r_.Fail("GENERATE expects an increasing range and a positive step");
    // Labels beyond the largest the part defines name nothing: the range stops there.
    const Part* part = scope && PartNamed(scope->part) ? PartNamed(scope->part) : &Current();
    long largest = 0;
    if (node_set) {
      for (long label : part->labels) largest = std::max(largest, label);
    } else {
      for (const AbaqusElement& e : part->elements) largest = std::max(largest, e.label);
    }
    for (long v = first; v <= std::min(last, largest); v += step) target(scope).insert(v);
    return;
  }
  for (std::string_view s : f) {
    if (s.empty()) continue;
    if (std::isdigit(static_cast<unsigned char>(s[0])) || s[0] == '-' || s[0] == '+') {
      target(scope).insert(IntegerField(r_, s));
      continue;
    }
    const std::string word = UpperCase(s);
    const size_t dot = word.find('.');
    if (in_assembly_ && scope == nullptr && dot != std::string::npos) {  // "Instance.label" or "Instance.SET"
      Instance* instance = instance_named(word.substr(0, dot));
      const std::string rest = word.substr(dot + 1);
      if (!rest.empty() && std::isdigit(static_cast<unsigned char>(rest[0]))) {
        target(instance).insert(IntegerField(r_, rest));
      } else {
        const Part* part = PartNamed(instance->part);
        if (!part) r_.Fail("instance " + instance->name + " places part " + instance->part + ", which is not defined");
        const auto& sets = node_set ? part->nsets : part->elsets;
        auto it = sets.find(rest);
        if (it == sets.end()) r_.Fail("part " + instance->part + " has no set " + rest);
        target(instance).insert(it->second.begin(), it->second.end());
      }
      continue;
    }
    std::map<std::string, std::set<long>>& sets =
        scope ? (node_set ? scope->nsets : scope->elsets) : (node_set ? Current().nsets : Current().elsets);
    auto it = sets.find(word);
    if (it == sets.end()) r_.Fail("'" + std::string(s) + "' is neither a label nor a set defined before");
    const std::set<long> copy = it->second;
    target(scope).insert(copy.begin(), copy.end());
  }
}

void DeckParser::OnData(const std::string& line) {
  if (data_ == Data::kNone) return;
  const std::vector<std::string_view> f = CommaFields(line);
  if (data_ == Data::kInstance) {
    Instance& instance = instances_[size_t(in_instance_)];
    std::vector<double> v;
    for (std::string_view s : f)
      if (!s.empty()) v.push_back(NumberField(r_, s));
    if (instance.placement_lines == 0) {
      if (v.size() != 3) r_.Fail("expected the instance's translation 'x, y, z'");
      instance.t = Eigen::Vector3d(v[0], v[1], v[2]);
    } else if (instance.placement_lines == 1) {
      if (v.size() != 7) r_.Fail("expected the instance's rotation 'ax, ay, az, bx, by, bz, angle'");
      const Eigen::Vector3d a(v[0], v[1], v[2]), b(v[3], v[4], v[5]);
      if ((b - a).norm() == 0.0) r_.Fail("the rotation axis has two equal points");
      // Abaqus: translate, then rotate about the axis through a and b by the angle (degrees).
      const Eigen::Matrix3d R = Eigen::AngleAxisd(v[6] * M_PI / 180.0, (b - a).normalized()).toRotationMatrix();
      instance.t = R * (instance.t - a) + a;
      instance.R = R * instance.R;
    } else {
      r_.Fail("an instance takes at most two lines (translation, rotation)");
    }
    ++instance.placement_lines;
    return;
  }
  if (in_assembly_ && in_instance_ < 0 && (data_ == Data::kNode || data_ == Data::kElement)) {
    // Reference points and assembly-level elements: not part of any instance's mesh.
    assembly_nodes_ += data_ == Data::kNode;
    if (data_ == Data::kElement) r_.Fail("elements at the assembly level (connectors, springs) are not read");
    return;
  }
  Part& part = Current();
  if (data_ == Data::kNode) {
    // "label, x, y[, z[, normal's three direction cosines]]"; a trailing comma is allowed.
    std::vector<std::string_view> node = f;
    while (!node.empty() && node.back().empty()) node.pop_back();
    if (node.size() < 3 || node.size() > 7) r_.Fail("expected 'label, x, y[, z]', got '" + line + "'");
    part.labels.push_back(IntegerField(r_, node[0]));
    part.x.emplace_back(NumberField(r_, node[1]), NumberField(r_, node[2]),
                        node.size() >= 4 ? NumberField(r_, node[3]) : 0.0);
    if (!node_set_.empty()) part.nsets[node_set_].insert(part.labels.back());
  } else if (data_ == Data::kElement) {
    for (std::string_view field : f)
      if (!field.empty()) pending_.emplace_back(field);
    const int known = KnownNodeCount(element_type_);
    const bool trailing_comma = !f.empty() && f.back().empty();
    if (trailing_comma || (known > 0 && long(pending_.size()) < known + 1)) return;  // continues
    const std::vector<std::string> all = std::move(pending_);
    pending_.clear();
    if (all.size() < 2) r_.Fail("expected 'label, node, node, ...', got '" + line + "'");
    AbaqusElement e;
    e.type = element_type_;
    e.label = IntegerField(r_, all[0]);
    for (size_t i = 1; i < all.size(); ++i) e.nodes.push_back(IntegerField(r_, all[i]));
    if (known > 0 && long(e.nodes.size()) != known) {
      r_.Fail("element " + std::to_string(e.label) + " of type " + e.type + " has " + std::to_string(e.nodes.size()) +
              " nodes, not " + std::to_string(known));
    }
    if (!element_set_.empty()) part.elsets[element_set_].insert(e.label);
    part.elements.push_back(std::move(e));
    part.element_lines.push_back(keyword_line_);
  } else {
    AddSetEntries(f);
  }
}

AbaqusMesh DeckParser::Place(const Instance& instance) const {
  const Part* part = PartNamed(instance.part);
  if (!part)
    throw InputError(r_.path() + ": instance " + instance.name + " places part " + instance.part +
                     ", which the deck does not define");
  AbaqusMesh mesh;
  mesh.name = instance.name;
  std::vector<size_t> order(part->labels.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return part->labels[a] < part->labels[b]; });
  mesh.nodes.resize(long(order.size()), 3);
  std::unordered_map<long, int> index;
  for (size_t i = 0; i < order.size(); ++i) {
    const long label = part->labels[order[i]];
    if (!index.emplace(label, int(i)).second)
      throw InputError(r_.path() + ": part " + part->name + " defines node " + std::to_string(label) + " twice");
    mesh.labels.push_back(label);
    mesh.nodes.row(long(i)) = (instance.R * part->x[order[i]] + instance.t).transpose();
  }
  std::unordered_map<long, size_t> element_of;
  for (size_t e = 0; e < part->elements.size(); ++e) {
    for (long label : part->elements[e].nodes)
      if (!index.count(label)) {
        throw InputError(r_.path() + ":" + std::to_string(part->element_lines[e]) + ": element " +
                         std::to_string(part->elements[e].label) + " uses node " + std::to_string(label) +
                         ", which the part does not define");
      }
    element_of[part->elements[e].label] = e;
  }
  mesh.elements = part->elements;
  mesh.element_lines = part->element_lines;
  auto add_nodes = [&](const std::map<std::string, std::set<long>>& sets) {
    for (const auto& [name, labels] : sets) {
      std::vector<int>& out = mesh.node_sets[name];
      for (long label : labels) {
        auto it = index.find(label);
        if (it == index.end())
          throw InputError(r_.path() + ": node set " + name + " names node " + std::to_string(label) + ", which part " +
                           part->name + " does not define");
        out.push_back(it->second);
      }
    }
  };
  auto add_elements = [&](const std::map<std::string, std::set<long>>& sets) {
    for (const auto& [name, labels] : sets) {
      if (mesh.node_sets.count(name)) continue;  // a node set of the same name wins
      std::set<int> nodes;
      for (long label : labels) {
        auto it = element_of.find(label);
        if (it == element_of.end()) continue;  // an element set may name elements of no part's mesh
        for (long n : part->elements[it->second].nodes) nodes.insert(index.at(n));
      }
      mesh.node_sets[name].assign(nodes.begin(), nodes.end());
    }
  };
  add_nodes(part->nsets);
  add_nodes(instance.nsets);
  add_elements(part->elsets);
  add_elements(instance.elsets);
  std::map<std::string, std::vector<int>> spelled;
  for (auto& [name, set] : mesh.node_sets) {
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
    auto it = spelling_.find(name);
    spelled[it == spelling_.end() ? name : it->second] = std::move(set);
  }
  mesh.node_sets = std::move(spelled);
  return mesh;
}

AbaqusDeck DeckParser::Parse() {
  std::string line;
  while (r_.Next(&line, "**")) {
    const size_t first = line.find_first_not_of(" \t");
    if (line[first] == '*') {
      if (!pending_.empty()) r_.Fail("the element on the lines above is not complete");
      const Keyword k = ParseKeyword(line.substr(first));
      if (k.name == "STEP") break;
      OnKeyword(k);
    } else {
      OnData(line);
    }
  }
  if (!pending_.empty()) r_.Fail("the file ends inside an element's data line");
  AbaqusDeck deck;
  deck.path = r_.path();
  deck.assembly = !instances_.empty();
  deck.assembly_nodes = assembly_nodes_;
  if (!deck.assembly) {
    Instance whole;  // a flat deck: its top level, in place
    whole.part = "";
    deck.instances.push_back(Place(whole));
  }
  for (const Instance& instance : instances_) deck.instances.push_back(Place(instance));
  long nodes = 0;
  for (const AbaqusMesh& m : deck.instances) nodes += long(m.labels.size());
  if (nodes == 0) throw InputError(r_.path() + ": no nodes (*Node) in the deck");
  return deck;
}

}  // namespace

AbaqusDeck ReadAbaqusDeck(const std::string& path) { return DeckParser(path).Parse(); }

bool HasInstances(const std::string& path) {
  LineReader r(path, "Abaqus deck");
  std::string line;
  while (r.Next(&line, "**")) {
    const size_t first = line.find_first_not_of(" \t");
    if (line[first] != '*') continue;
    const std::string name = ParseKeyword(line.substr(first)).name;
    if (name == "INSTANCE") return true;
    if (name == "STEP") return false;
  }
  return false;
}

int PickInstance(const AbaqusDeck& deck, const std::string& name, const std::string& where) {
  std::string names;
  for (const AbaqusMesh& m : deck.instances) names += (names.empty() ? "" : ", ") + m.name;
  if (name.empty()) {
    if (deck.instances.size() == 1) return 0;
    throw InputError(where + ": " + deck.path + " has " + std::to_string(deck.instances.size()) + " instances (" +
                     names + "): name one with matrices.instance");
  }
  for (size_t i = 0; i < deck.instances.size(); ++i)
    if (UpperCase(deck.instances[i].name) == UpperCase(name)) return int(i);
  throw InputError(where + ": " + deck.path + " has no instance '" + name + "'" +
                   (deck.assembly ? " (it has " + names + ")" : " (it has no *Instance: leave instance out)"));
}

unsigned ElementDofMask(const std::string& type) {
  const std::string t = UpperCase(type);
  auto starts = [&](const char* p) { return t.rfind(p, 0) == 0; };
  const bool hybrid = t.find('H', 3) != std::string::npos && (starts("C3D") || starts("B3"));
  if (hybrid) return 0;  // Lagrange multipliers on Abaqus internal nodes
  if (starts("C3D") || starts("SC6") || starts("SC8") || starts("M3D") || starts("T3D") || t == "MASS") return 0x7;
  if (t == "ROTARYI") return 0x38;
  if (t.size() > 2 && t.compare(t.size() - 2, 2, "OS") == 0) return 0;  // open sections: warping DOF 7
  if (t.find("R5") != std::string::npos || starts("STRI65")) return 0;  // five-DOF shells: local rotations
  if (starts("S3") || starts("S4") || starts("S8") || starts("S9") || starts("B31") || starts("B32") || starts("B33"))
    return 0x3f;
  return 0;
}

std::vector<AbaqusEquation> CoordinateEquations(const AbaqusDeck& deck) {
  std::vector<AbaqusEquation> out;
  for (size_t i = 0; i < deck.instances.size(); ++i) {
    const AbaqusMesh& m = deck.instances[i];
    std::unordered_map<long, int> index;
    for (size_t s = 0; s < m.labels.size(); ++s) index[m.labels[s]] = int(s);
    std::vector<unsigned> mask(m.labels.size(), 0);
    for (size_t e = 0; e < m.elements.size(); ++e) {
      const unsigned dofs = ElementDofMask(m.elements[e].type);
      if (dofs == 0) {
        throw InputError(deck.path + ":" + std::to_string(m.element_lines[e]) + ": element type " + m.elements[e].type +
                         ": its equations in Abaqus' coordinate output cannot be derived from the deck "
                         "(hybrid, five-DOF shell, planar, connector or other types with internal nodes); "
                         "export with FORMAT=MATRIX INPUT (node and DOF labels)");
      }
      for (long n : m.elements[e].nodes) mask[size_t(index.at(n))] |= dofs;
    }
    for (size_t s = 0; s < m.labels.size(); ++s)
      for (int c = 0; c < 6; ++c)
        if (mask[s] & (1u << c)) out.push_back({int(i), m.labels[s], c});
  }
  return out;
}

}  // namespace femb
