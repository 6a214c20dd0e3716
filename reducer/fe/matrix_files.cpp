// Readers and writers of FE matrix files (reducer/fe/matrix_files.h).
#include "reducer/fe/matrix_files.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string_view>
#include <unordered_map>

#include "formats/abaqus_deck.h"
#include "formats/input_error.h"
#include "formats/text_lines.h"

namespace femb {

std::string ShortNumber(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

namespace {

constexpr const char* kComponentNames[6] = {"u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z"};

struct Entry {
  long row, col;  // 0-based
  double value;
  long line;
};

// One row of the DOF map: node label and component 1..6.
void AddDof(const LineReader& r, long node, long c, ImportedMatrices* out) {
  if (c < 1 || c > 6)
    r.Fail("component " + std::to_string(c) + " is not 1..6 (u_x, u_y, u_z, theta_x, theta_y, theta_z)");
  out->node.push_back(node);
  out->component.push_back(int(c - 1));
}

// "row column value" lines (1-based) up to the end of the file, into 0-based entries.
void ReadCoordinateEntries(LineReader* r, long rows, long cols, const std::string& range, std::vector<Entry>* entries,
                           const std::string& comment = "") {
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

std::string DofName(long node, int component) {
  return "node " + std::to_string(node) + " " + kComponentNames[component];
}

// Row/column entries (0-based) -> the symmetric matrix: one triangle is mirrored; both are
// checked to be symmetric to 1e-8 of the largest entry.
SparseMatrix Symmetric(const std::vector<Entry>& entries, long n, const std::string& path,
                       const std::vector<long>& node, const std::vector<int>& component, std::string* stored) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(entries.size());
  long upper = 0, lower = 0;
  for (const Entry& e : entries) {
    t.emplace_back(int(e.row), int(e.col), e.value);
    upper += e.row < e.col;
    lower += e.row > e.col;
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  const SparseMatrix At = A.transpose();
  if (upper > 0 && lower > 0) {
    *stored = "both triangles";
    const SparseMatrix D = A - At;
    double max_a = 0.0;
    for (int k = 0; k < A.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(A, k); it; ++it) max_a = std::max(max_a, std::abs(it.value()));
    for (int k = 0; k < D.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(D, k); it; ++it)
        if (std::abs(it.value()) > 1e-8 * max_a) {
          char b[200];
          std::snprintf(b, sizeof b, " differ by %.3g (%.2g of the largest entry): the matrix is not symmetric",
                        std::abs(it.value()), std::abs(it.value()) / max_a);
          throw InputError(path + ": entries (" + DofName(node[size_t(it.row())], component[size_t(it.row())]) + ", " +
                           DofName(node[size_t(it.col())], component[size_t(it.col())]) + ") and its transpose" + b);
        }
    return SparseMatrix(0.5 * (A + At));
  }
  *stored = upper > 0 ? "upper triangle" : lower > 0 ? "lower triangle" : "diagonal";
  SparseMatrix diagonal(n, n);
  std::vector<Eigen::Triplet<double>> d;
  for (long i = 0; i < n; ++i)
    if (A.coeff(i, i) != 0.0) d.emplace_back(int(i), int(i), A.coeff(i, i));
  diagonal.setFromTriplets(d.begin(), d.end());
  return SparseMatrix(A + At - diagonal);
}

// CalculiX: "row col value" lines, 1-based, and the .dof file "node.component".
void ReadCalculix(const MatricesSpec& spec, ImportedMatrices* out, std::vector<Entry>* k, std::vector<Entry>* m) {
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

// Abaqus: "row node, row dof, column node, column dof, value"; rows numbered by (node, dof).
void ReadAbaqus(const MatricesSpec& spec, ImportedMatrices* out, std::vector<Entry>* k, std::vector<Entry>* m) {
  struct Raw {
    long n1, d1, n2, d2;
    double v;
  };
  std::map<std::pair<long, int>, long> index;
  std::vector<Raw> raw_k, raw_m;
  std::string line;
  for (auto [path, raw] : {std::pair{&spec.stiffness, &raw_k}, std::pair{&spec.mass, &raw_m}}) {
    LineReader r(*path, "matrix file");
    while (r.Next(&line, "*")) {
      const std::vector<std::string_view> f = Fields(line);
      if (f.size() != 5) r.Fail("expected 'node, dof, node, dof, value', got '" + line + "'");
      Raw e{IntegerField(r, f[0]), IntegerField(r, f[1]), IntegerField(r, f[2]), IntegerField(r, f[3]),
            NumberField(r, f[4])};
      for (long label : {e.n1, e.n2}) {
        if (label <= 0) {
          r.Fail("node " + std::to_string(label) +
                 " is an Abaqus internal node (Lagrange multipliers of hybrid elements, "
                 "MPCs or connectors): export a model without them");
        }
      }
      for (long d : {e.d1, e.d2}) {
        if (d < 1 || d > 6) r.Fail("dof " + std::to_string(d) + " is not 1..6 (only displacements and rotations)");
      }
      index[{e.n1, int(e.d1 - 1)}] = 0;
      index[{e.n2, int(e.d2 - 1)}] = 0;
      raw->push_back(e);
    }
  }
  long row = 0;
  for (auto& [key, value] : index) {
    value = row++;
    out->node.push_back(key.first);
    out->component.push_back(key.second);
  }
  for (auto [raw, entries] : {std::pair{&raw_k, k}, std::pair{&raw_m, m}})
    for (const Raw& e : *raw) entries->push_back({index[{e.n1, int(e.d1 - 1)}], index[{e.n2, int(e.d2 - 1)}], e.v, 0});
}

// Abaqus FORMAT=COORDINATE: "row column value" on equation numbers, which the deck numbers
// (formats/abaqus_deck.h); the rows of the part's instance are kept, the other instances' dropped.
void ReadAbaqusCoordinate(const MatricesSpec& spec, ImportedMatrices* out, std::vector<Entry>* k,
                          std::vector<Entry>* m) {
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

// Matrix Market coordinate real (symmetric or general) and the CSV "node, component" map.
void ReadMatrixMarket(const MatricesSpec& spec, ImportedMatrices* out, std::vector<Entry>* k, std::vector<Entry>* m) {
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
  for (auto [path, entries] : {std::pair{&spec.stiffness, k}, std::pair{&spec.mass, m}}) {
    LineReader r(*path, "matrix file");
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
    if (rows != n)
      r.Fail("the matrix has " + std::string(size[0]) + " rows but " + spec.dofs + " maps " + std::to_string(n));
    const size_t before = entries->size();
    ReadCoordinateEntries(&r, n, n, "1.." + std::to_string(n), entries, "%");
    const long count = long(entries->size() - before);
    if (count != nnz)
      r.Fail("the size line announces " + std::to_string(nnz) + " entries, the file has " + std::to_string(count));
  }
}

}  // namespace

ImportedMatrices ReadImportedMatrices(const MatricesSpec& spec) {
  ImportedMatrices out;
  std::vector<Entry> k, m;
  if (spec.format == MatrixFormat::kCalculix) {
    ReadCalculix(spec, &out, &k, &m);
  } else if (spec.format == MatrixFormat::kAbaqusCoordinate ||
             (spec.format == MatrixFormat::kAbaqus && IsAbaqusCoordinate(spec.stiffness))) {
    ReadAbaqusCoordinate(spec, &out, &k, &m);
  } else if (spec.format == MatrixFormat::kAbaqus) {
    ReadAbaqus(spec, &out, &k, &m);
  } else {
    ReadMatrixMarket(spec, &out, &k, &m);
  }
  const long n = long(out.node.size());
  {
    std::map<std::pair<long, int>, long> seen;
    for (long r = 0; r < n; ++r) {
      auto [it, fresh] = seen.emplace(std::pair{out.node[size_t(r)], out.component[size_t(r)]}, r);
      if (!fresh) {
        throw InputError(spec.dofs + ": " + DofName(out.node[size_t(r)], out.component[size_t(r)]) +
                         " appears twice (rows " + std::to_string(it->second + 1) + " and " + std::to_string(r + 1) +
                         ")");
      }
    }
  }
  std::string stored_m;
  out.K = Symmetric(k, n, spec.stiffness, out.node, out.component, &out.stored);
  out.M = Symmetric(m, n, spec.mass, out.node, out.component, &stored_m);
  for (long r = 0; r < n; ++r) {
    const double kd = out.K.coeff(r, r), md = out.M.coeff(r, r);
    const std::string dof = DofName(out.node[size_t(r)], out.component[size_t(r)]);
    if (kd < 0)
      throw InputError(spec.stiffness + ": the diagonal of " + dof + " is negative (" + ShortNumber(kd) + ")");
    if (md < 0) throw InputError(spec.mass + ": the diagonal of " + dof + " is negative (" + ShortNumber(md) + ")");
    if (kd == 0) {
      throw InputError(spec.stiffness + ": " + dof +
                       " has no stiffness (zero diagonal): a node of no element, or a "
                       "shell's drilling rotation; leave it out of the export");
    }
  }
  return out;
}

Eigen::MatrixXd ReadShapeMatrix(const std::string& path, long rows) {
  LineReader r(path, "deformation shapes file");
  std::string line;
  if (!r.Next(&line, "")) r.Fail("empty file");
  std::string lower = line;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  const bool array = lower.find(" array") != std::string::npos;
  if (lower.rfind("%%matrixmarket", 0) != 0 || (!array && lower.find("coordinate") == std::string::npos) ||
      lower.find("real") == std::string::npos || lower.find("general") == std::string::npos) {
    r.Fail("expected '%%MatrixMarket matrix array real general' (or coordinate), got '" + line + "'");
  }
  if (!r.Next(&line, "%")) r.Fail("no size line");
  const std::vector<std::string_view> size = Fields(line);
  if (size.size() != (array ? 2u : 3u))
    r.Fail("expected the size line 'rows columns" + std::string(array ? "'" : " entries'"));
  const long n = IntegerField(r, size[0]), m = IntegerField(r, size[1]);
  if (n != rows) {
    r.Fail("the shapes have " + std::string(size[0]) + " rows but the matrices have " + std::to_string(rows) +
           " DOFs (one row per DOF, in the matrices' order)");
  }
  if (m <= 0) r.Fail("no shapes (columns)");
  // Before allocating n x m: more shapes than DOFs cannot be independent, and an array file
  // holds at least 2 bytes per value (a digit and a newline).
  if (m > n)
    r.Fail("the file announces " + std::to_string(m) + " shapes for " + std::to_string(n) +
           " DOFs (at most one per DOF)");
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (array && !ec && double(bytes) < 2.0 * double(n) * double(m)) {
    r.Fail("the file is too short for the " + std::to_string(n) + " x " + std::to_string(m) +
           " values its size line announces");
  }
  Eigen::MatrixXd V = Eigen::MatrixXd::Zero(n, m);
  if (array) {
    for (long j = 0; j < m; ++j)
      for (long i = 0; i < n; ++i) {
        if (!r.Next(&line, "%"))
          r.Fail("the file ends after " + std::to_string(j * n + i) + " of " + std::to_string(n * m) + " values");
        const std::vector<std::string_view> f = Fields(line);
        if (f.size() != 1) r.Fail("expected one value per line (array format, column by column), got '" + line + "'");
        V(i, j) = NumberField(r, f[0]);
      }
  } else {
    std::vector<Entry> entries;
    ReadCoordinateEntries(&r, n, m, "the " + std::string(size[0]) + " x " + std::string(size[1]) + " matrix", &entries,
                          "%");
    for (const Entry& e : entries) V(e.row, e.col) = e.value;
  }
  return V;
}

std::vector<std::string> WriteMatrices(MatrixFormat format, const SparseMatrix& K, const SparseMatrix& M,
                                       const std::vector<long>& node, const std::vector<int>& component,
                                       const std::string& directory, const std::string& stem) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  const std::filesystem::path dir(directory);
  std::vector<std::string> written;
  // Atomic per file: a temporary name in the same folder, renamed when complete.
  auto write = [&](const std::string& name, const std::function<void(std::ostream&)>& body) {
    const std::string path = (dir / name).string();
    const std::string tmp = path + ".tmp" + std::to_string(::getpid());
    {
      std::ofstream out(tmp);
      if (!out) throw InputError(directory + ": cannot write " + name);
      out.precision(17);
      body(out);
      if (!out) throw InputError(directory + ": cannot write " + name);
    }
    std::filesystem::rename(tmp, path);
    written.push_back(path);
  };
  auto upper = [](const SparseMatrix& A, const std::function<void(long, long, double)>& emit) {
    for (int j = 0; j < A.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(A, j); it; ++it)
        if (it.row() <= j) emit(it.row(), j, it.value());
  };
  auto count_upper = [&](const SparseMatrix& A) {
    long c = 0;
    upper(A, [&](long, long, double) { ++c; });
    return c;
  };
  if (format == MatrixFormat::kCalculix) {
    for (auto [ext, A] : {std::pair{".sti", &K}, std::pair{".mas", &M}})
      write(stem + ext, [&, A = A](std::ostream& out) {
        upper(*A, [&](long i, long j, double v) { out << i + 1 << ' ' << j + 1 << ' ' << v << '\n'; });
      });
    write(stem + ".dof", [&](std::ostream& out) {
      for (size_t r = 0; r < node.size(); ++r) out << node[r] << '.' << component[r] + 1 << '\n';
    });
  } else if (format == MatrixFormat::kAbaqusCoordinate) {
    // Equation numbers: the rows in order, which is Abaqus' numbering for a deck whose nodes
    // carry these DOFs (formats/abaqus_deck.h).
    for (auto [suffix, A] : {std::pair{"_STIF1.mtx", &K}, std::pair{"_MASS1.mtx", &M}})
      write(stem + suffix, [&, A = A](std::ostream& out) {
        upper(*A, [&](long i, long j, double v) { out << i + 1 << ' ' << j + 1 << "  " << v << '\n'; });
      });
  } else if (format == MatrixFormat::kAbaqus) {
    for (auto [suffix, A] : {std::pair{"_STIF1.mtx", &K}, std::pair{"_MASS1.mtx", &M}})
      write(stem + suffix, [&, A = A](std::ostream& out) {
        upper(*A, [&](long i, long j, double v) {
          out << node[size_t(i)] << ',' << component[size_t(i)] + 1 << ", " << node[size_t(j)] << ','
              << component[size_t(j)] + 1 << ", " << v << '\n';
        });
      });
  } else {  // kMatrixMarket
    // Symmetric storage is the lower triangle: entry (j, i) for each upper (i, j).
    for (auto [suffix, A] : {std::pair{"_K.mtx", &K}, std::pair{"_M.mtx", &M}})
      write(stem + suffix, [&, A = A](std::ostream& out) {
        out << "%%MatrixMarket matrix coordinate real symmetric\n% written by femb-reduce --export-matrices\n";
        out << A->rows() << ' ' << A->cols() << ' ' << count_upper(*A) << '\n';
        upper(*A, [&](long i, long j, double v) { out << j + 1 << ' ' << i + 1 << ' ' << v << '\n'; });
      });
    write(stem + "_dofs.csv", [&](std::ostream& out) {
      out << "node,component\n";
      for (size_t r = 0; r < node.size(); ++r) out << node[r] << ',' << component[r] + 1 << '\n';
    });
  }
  return written;
}
}  // namespace femb
