// The readers of the calculix, abaqus and matrix_market formats (reducer/fe/matrix_readers.h).
#include "reducer/fe/matrix_readers.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <string_view>

#include "formats/abaqus_deck.h"
#include "formats/input_error.h"

namespace femb {

void AddDof(const LineReader& r, long node, long c, ImportedMatrices* out) {
  if (c < 1 || c > 6)
    r.Fail("component " + std::to_string(c) + " is not 1..6 (u_x, u_y, u_z, theta_x, theta_y, theta_z)");
  out->node.push_back(node);
  out->component.push_back(int(c - 1));
}

void ReadCoordinateEntries(LineReader* r, long rows, long cols, const std::string& range,
                           std::vector<MatrixEntry>* entries, const std::string& comment) {
  std::string line;
  while (r->Next(&line, comment)) {
    const std::vector<std::string_view> f = Fields(line);
    if (f.size() != 3) r->Fail("expected 'row column value', got '" + line + "'");
    const long i = IntegerField(*r, f[0]), j = IntegerField(*r, f[1]);
    if (i < 1 || i > rows || j < 1 || j > cols) {
      r->Fail("index (" + std::string(f[0]) + ", " + std::string(f[1]) + ") outside " + range);
    }
    entries->push_back({i - 1, j - 1, NumberField(*r, f[2]), r->number()});
  }
}

// CalculiX: "row col value" lines, 1-based, and the .dof file "node.component".
void ReadCalculix(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                  std::vector<MatrixEntry>* m) {
  LineReader dofs(spec.dofs, "DOF map");
  std::string line;
  while (dofs.Next(&line, "")) {
    const std::vector<std::string_view> f = Fields(line);
    const size_t dot = f.empty() ? std::string::npos : f[0].find('.');
    if (f.size() != 1 || dot == std::string::npos) dofs.Fail("expected node.component (e.g. 12.3), got '" + line + "'");
    const long node = IntegerField(dofs, f[0].substr(0, dot));
    const long c = IntegerField(dofs, f[0].substr(dot + 1));
    AddDof(dofs, node, c, out);
  }
  if (out->node.empty()) throw InputError(spec.dofs + ": no DOFs");
  const long n = long(out->node.size());
  for (auto [path, entries] : {std::pair{&spec.stiffness, k}, std::pair{&spec.mass, m}}) {
    LineReader r(*path, "matrix file");
    ReadCoordinateEntries(&r, n, n, "the " + std::to_string(n) + " DOFs of " + spec.dofs, entries);
  }
}

void ReadMatrixMarketFile(const std::string& path, long n, const std::string& dofs, std::vector<MatrixEntry>* entries) {
  LineReader r(path, "matrix file");
  std::string line;
  if (!r.Next(&line, "")) r.Fail("empty file");
  std::string lower = line;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  if (lower.rfind("%%matrixmarket", 0) != 0 || lower.find("coordinate") == std::string::npos ||
      lower.find("real") == std::string::npos ||
      (lower.find("symmetric") == std::string::npos && lower.find("general") == std::string::npos)) {
    r.Fail("expected '%%MatrixMarket matrix coordinate real symmetric' (or general), got '" + line + "'");
  }
  if (!r.Next(&line, "%")) r.Fail("no size line");
  const std::vector<std::string_view> size = Fields(line);
  if (size.size() != 3) r.Fail("expected 'rows columns entries', got '" + line + "'");
  const long rows = IntegerField(r, size[0]), cols = IntegerField(r, size[1]), nnz = IntegerField(r, size[2]);
  if (rows != cols) r.Fail("the matrix is " + std::string(size[0]) + " x " + std::string(size[1]) + ", not square");
  if (rows != n) r.Fail("the matrix has " + std::string(size[0]) + " rows but " + dofs + " maps " + std::to_string(n));
  const size_t before = entries->size();
  ReadCoordinateEntries(&r, n, n, "1.." + std::to_string(n), entries, "%");
  const long count = long(entries->size() - before);
  if (count != nnz)
    r.Fail("the size line announces " + std::to_string(nnz) + " entries, the file has " + std::to_string(count));
}

void IndexLabelledEntries(const std::vector<LabelledEntry>& k_raw, const std::vector<LabelledEntry>& m_raw,
                          ImportedMatrices* out, std::vector<MatrixEntry>* k, std::vector<MatrixEntry>* m) {
  std::map<std::pair<long, int>, long> index;
  for (const auto* raw : {&k_raw, &m_raw})
    for (const LabelledEntry& e : *raw) {
      index[{e.node_i, e.component_i}] = 0;
      index[{e.node_j, e.component_j}] = 0;
    }
  long row = 0;
  for (auto& [key, value] : index) {
    value = row++;
    out->node.push_back(key.first);
    out->component.push_back(key.second);
  }
  for (auto [raw, entries] : {std::pair{&k_raw, k}, std::pair{&m_raw, m}})
    for (const LabelledEntry& e : *raw)
      entries->push_back({index[{e.node_i, e.component_i}], index[{e.node_j, e.component_j}], e.value, e.line});
}

namespace {

// Abaqus' matrix input form: "row node, row dof, column node, column dof, value"; rows numbered
// by (node, dof).
void ReadAbaqusLabelled(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                        std::vector<MatrixEntry>* m) {
  std::vector<LabelledEntry> raw_k, raw_m;
  std::string line;
  for (auto [path, raw] : {std::pair{&spec.stiffness, &raw_k}, std::pair{&spec.mass, &raw_m}}) {
    LineReader r(*path, "matrix file");
    while (r.Next(&line, "*")) {
      const std::vector<std::string_view> f = Fields(line);
      if (f.size() != 5) r.Fail("expected 'node, dof, node, dof, value', got '" + line + "'");
      const long n1 = IntegerField(r, f[0]), d1 = IntegerField(r, f[1]), n2 = IntegerField(r, f[2]),
                 d2 = IntegerField(r, f[3]);
      for (long label : {n1, n2}) {
        if (label <= 0) {
          r.Fail("node " + std::to_string(label) +
                 " is an Abaqus internal node (Lagrange multipliers of hybrid elements, "
                 "MPCs or connectors): export a model without them");
        }
      }
      for (long d : {d1, d2}) {
        if (d < 1 || d > 6) r.Fail("dof " + std::to_string(d) + " is not 1..6 (only displacements and rotations)");
      }
      raw->push_back({n1, int(d1 - 1), n2, int(d2 - 1), NumberField(r, f[4]), r.number()});
    }
  }
  IndexLabelledEntries(raw_k, raw_m, out, k, m);
}

// Abaqus FORMAT=COORDINATE: "row column value" on equation numbers, which the deck numbers
// (formats/abaqus_deck.h); the rows of the part's instance are kept, the other instances' dropped.
void ReadAbaqusCoordinate(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                          std::vector<MatrixEntry>* m) {
  if (spec.deck.empty()) {
    throw InputError(spec.stiffness +
                     ": Abaqus' coordinate form (row, column, value) numbers equations, not nodes: make the part's "
                     "geometry file the Abaqus deck (.inp) the matrices were generated from");
  }
  const AbaqusDeck deck = ReadAbaqusDeck(spec.deck);
  const int chosen = PickInstance(deck, spec.instance, spec.where);
  const std::vector<AbaqusEquation> equations = CoordinateEquations(deck);
  const long n_all = long(equations.size());
  std::vector<long> local(size_t(n_all), -1);
  for (long e = 0; e < n_all; ++e) {
    if (equations[size_t(e)].instance != chosen) continue;
    local[size_t(e)] = long(out->node.size());
    out->node.push_back(equations[size_t(e)].node);
    out->component.push_back(equations[size_t(e)].component);
  }
  const std::string reference_points =
      deck.assembly_nodes > 0 ? ", and its " + std::to_string(deck.assembly_nodes) + " reference points carry none"
                              : "";
  const std::string why =
      "Abaqus adds equations for internal nodes of hybrid elements, MPCs and connectors: export a model without "
      "them, or with FORMAT=MATRIX INPUT";
  const std::string hint = " (the deck's nodes and elements give " + std::to_string(n_all) + " equations" +
                           reference_points + "; " + why + ")";
  std::string line;
  for (auto [path, entries] : {std::pair{&spec.stiffness, k}, std::pair{&spec.mass, m}}) {
    LineReader r(*path, "matrix file");
    long largest = 0;
    while (r.Next(&line, "*")) {
      const std::vector<std::string_view> f = Fields(line);
      if (f.size() != 3) r.Fail("expected 'row, column, value' (Abaqus coordinate form), got '" + line + "'");
      const long i = IntegerField(r, f[0]), j = IntegerField(r, f[1]);
      const double v = NumberField(r, f[2]);
      if (i < 1 || j < 1 || i > n_all || j > n_all)
        r.Fail("equation " + std::to_string(i < 1 || i > n_all ? i : j) + " is outside 1.." + std::to_string(n_all) +
               hint);
      largest = std::max({largest, i, j});
      const long li = local[size_t(i - 1)], lj = local[size_t(j - 1)];
      if (li < 0 && lj < 0) continue;  // another instance's block
      if (li < 0 || lj < 0) {
        if (v == 0.0) continue;
        const AbaqusEquation& other = equations[size_t(li < 0 ? i - 1 : j - 1)];
        r.Fail("the entry couples instance " + deck.instances[size_t(chosen)].name + " to node " +
               std::to_string(other.node) + " of instance " + deck.instances[size_t(other.instance)].name +
               ": export the part alone");
      }
      entries->push_back({li, lj, v, r.number()});
    }
    if (path == &spec.stiffness && largest != n_all) {
      throw InputError(*path + ": the matrix numbers " + std::to_string(largest) + " equations, but " + spec.deck +
                       "'s nodes and elements give " + std::to_string(n_all) + reference_points + "; " + why);
    }
  }
}

// The first data line of an Abaqus matrix file has 3 fields in the coordinate form, 5 in the
// matrix input form.
bool IsAbaqusCoordinate(const std::string& path) {
  LineReader r(path, "matrix file");
  std::string line;
  return r.Next(&line, "*") && Fields(line).size() == 3;
}

}  // namespace

// Matrix Market coordinate real (symmetric or general) and the CSV "node, component" map.
void ReadMatrixMarket(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                      std::vector<MatrixEntry>* m) {
  LineReader dofs(spec.dofs, "DOF map");
  std::string line;
  bool first = true;
  while (dofs.Next(&line, "#")) {
    const std::vector<std::string_view> f = Fields(line);
    if (first && !f.empty() && !std::isdigit(static_cast<unsigned char>(f[0][0]))) {  // a header line
      first = false;
      continue;
    }
    first = false;
    if (f.size() != 2) dofs.Fail("expected 'node, component', got '" + line + "'");
    const long node = IntegerField(dofs, f[0]), c = IntegerField(dofs, f[1]);
    AddDof(dofs, node, c, out);
  }
  if (out->node.empty()) throw InputError(spec.dofs + ": no DOFs");
  const long n = long(out->node.size());
  for (auto [path, entries] : {std::pair{&spec.stiffness, k}, std::pair{&spec.mass, m}})
    ReadMatrixMarketFile(*path, n, spec.dofs, entries);
}

void ReadAbaqus(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                std::vector<MatrixEntry>* m) {
  if (spec.format == MatrixFormat::kAbaqusCoordinate || IsAbaqusCoordinate(spec.stiffness)) {
    ReadAbaqusCoordinate(spec, out, k, m);
  } else {
    ReadAbaqusLabelled(spec, out, k, m);
  }
}

}  // namespace femb
