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

#include "formats/input_error.h"
#include "formats/text_lines.h"
#include "reducer/fe/matrix_readers.h"

namespace femb {

std::string ShortNumber(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

namespace {

constexpr const char* kComponentNames[6] = {"u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z"};

std::string DofName(long node, int component) {
  return "node " + std::to_string(node) + " " + kComponentNames[component];
}

// Row/column entries (0-based) -> the symmetric matrix: one triangle is mirrored; both are
// checked to be symmetric to 1e-8 of the largest entry.
SparseMatrix Symmetric(const std::vector<MatrixEntry>& entries, long n, const std::string& path,
                       const std::vector<long>& node, const std::vector<int>& component, std::string* stored) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(entries.size());
  long upper = 0, lower = 0;
  for (const MatrixEntry& e : entries) {
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

}  // namespace

ImportedMatrices ReadImportedMatrices(const MatricesSpec& spec) {
  ImportedMatrices out;
  std::vector<MatrixEntry> k, m;
  if (spec.format == MatrixFormat::kCalculix) {
    ReadCalculix(spec, &out, &k, &m);
  } else if (spec.format == MatrixFormat::kAbaqus || spec.format == MatrixFormat::kAbaqusCoordinate) {
    ReadAbaqus(spec, &out, &k, &m);
  } else if (spec.format == MatrixFormat::kNastran) {
    ReadNastranDmig(spec, &out, &k, &m);
  } else if (spec.format == MatrixFormat::kAnsys) {
    ReadAnsys(spec, &out, &k, &m);
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
    std::vector<MatrixEntry> entries;
    ReadCoordinateEntries(&r, n, m, "the " + std::string(size[0]) + " x " + std::string(size[1]) + " matrix", &entries,
                          "%");
    for (const MatrixEntry& e : entries) V(e.row, e.col) = e.value;
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
    // carry these DOFs (formats/abaqus_deck.h). Both triangles, as Abaqus writes this form and
    // as readers that take it as it is (Exudyn's FEMinterface: numpy.loadtxt) need it.
    for (auto [suffix, A] : {std::pair{"_STIF1.mtx", &K}, std::pair{"_MASS1.mtx", &M}})
      write(stem + suffix, [&, A = A](std::ostream& out) {
        for (int j = 0; j < A->outerSize(); ++j)
          for (SparseMatrix::InnerIterator it(*A, j); it; ++it)
            out << it.row() + 1 << ' ' << j + 1 << "  " << it.value() << '\n';
      });
  } else if (format == MatrixFormat::kAbaqus) {
    for (auto [suffix, A] : {std::pair{"_STIF1.mtx", &K}, std::pair{"_MASS1.mtx", &M}})
      write(stem + suffix, [&, A = A](std::ostream& out) {
        upper(*A, [&](long i, long j, double v) {
          out << node[size_t(i)] << ',' << component[size_t(i)] + 1 << ", " << node[size_t(j)] << ','
              << component[size_t(j)] + 1 << ", " << v << '\n';
        });
      });
  } else {
    if (format != MatrixFormat::kMatrixMarket)
      throw InputError(directory + ": matrices are not written in the " + std::string(Name(format)) + " format");
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
