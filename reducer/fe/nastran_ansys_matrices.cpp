// The readers of the nastran and ansys formats (reducer/fe/matrix_readers.h).
//
// Nastran: DMIG bulk data entries (what PARAM,EXTOUT,DMIGPCH punches, or what a user writes for
// K2GG/M2GG): a header "DMIG NAME 0 IFO TIN TOUT POLAR - NCOL" and column entries "DMIG NAME GJ
// CJ - G1 C1 A1 B1" continued by "G2 C2 A2 B2 G3 C3 A3 B3", in small field (8 characters),
// large field (16, DMIG* and *) or free field (commas). Rows and columns are (grid, component),
// so the matrices carry their own DOF map.
//
// Ansys: the assembled matrices from the .full file as HBMAT writes them (Harwell-Boeing, RSA or
// RUA) or as *EXPORT,,MMF writes them (Matrix Market), with the mapping file HBMAT writes
// (Mapping=YES): "equation node label" rows, labels UX UY UZ ROTX ROTY ROTZ.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <string_view>

#include "formats/input_error.h"
#include "reducer/fe/matrix_readers.h"

namespace femb {
namespace {

// A Fortran or Nastran real: 1.5, -2.E+3, 1.0D-4, and exponents without a letter (3.+5, 1.2-3);
// nullopt for anything else or a value that is not finite.
std::optional<double> FortranReal(std::string_view text) {
  std::string t(TrimBlanks(text));
  for (size_t i = 1; i < t.size(); ++i) {
    const char before = t[i - 1];
    if ((t[i] == '+' || t[i] == '-') && (std::isdigit(static_cast<unsigned char>(before)) || before == '.')) {
      t.insert(i, 1, 'E');
      break;
    }
  }
  std::replace(t.begin(), t.end(), 'D', 'E');
  std::replace(t.begin(), t.end(), 'd', 'e');
  if (t.empty()) return std::nullopt;
  char* stop = nullptr;
  const double v = std::strtod(t.c_str(), &stop);
  if (*stop != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<long> Integer(std::string_view text) {
  const std::string t(TrimBlanks(text));
  if (t.empty()) return std::nullopt;
  char* stop = nullptr;
  const long v = std::strtol(t.c_str(), &stop, 10);
  if (*stop != '\0') return std::nullopt;
  return v;
}

// One bulk data entry: fields 2..9 of its first line and of each continuation, in order (large
// field lines give four).
struct Card {
  std::string name;  // upper case, without '*'
  std::vector<std::string> fields;
  long line;
};

// The line's name field and its data fields (8 small, 4 large; blanks kept).
std::pair<std::string, std::vector<std::string>> SplitBulkLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string name;
  const size_t dollar = line.find('$');
  const std::string_view text = std::string_view(line).substr(0, dollar);
  if (text.find(',') != std::string_view::npos) {  // free field
    const std::vector<std::string_view> f = CommaFields(text);
    name = UpperCase(f[0]);
    const size_t count = name.find('*') != std::string::npos ? 4 : 8;
    for (size_t k = 1; k < f.size() && fields.size() < count; ++k) fields.emplace_back(f[k]);
    fields.resize(count);
    return {name, fields};
  }
  name = UpperCase(TrimBlanks(text.substr(0, std::min<size_t>(8, text.size()))));
  const bool large = name.find('*') != std::string::npos;
  const size_t width = large ? 16 : 8, count = large ? 4 : 8;
  for (size_t k = 0; k < count; ++k) {
    const size_t start = 8 + k * width;
    fields.emplace_back(start < text.size() ? TrimBlanks(text.substr(start, width)) : std::string_view());
  }
  return {name, fields};
}

// The DMIG entries of a file (other entries and their continuations skipped).
std::vector<Card> DmigCards(LineReader* r) {
  std::vector<Card> cards;
  bool in_dmig = false;
  std::string line;
  while (r->Next(&line, "$")) {
    auto [name, fields] = SplitBulkLine(line);
    const bool continuation = name.empty() || name[0] == '+' || name[0] == '*';
    if (!continuation) {
      std::string bare = name;
      bare.erase(std::remove(bare.begin(), bare.end(), '*'), bare.end());
      in_dmig = bare == "DMIG";
      if (in_dmig) cards.push_back({bare, {}, r->number()});
    }
    if (in_dmig) cards.back().fields.insert(cards.back().fields.end(), fields.begin(), fields.end());
  }
  return cards;
}

struct DmigMatrix {
  std::string name;
  std::vector<LabelledEntry> entries;
};

// One DMIG column entry: "NAME GJ CJ - G1 C1 A1 B1 G2 C2 A2 B2 ...".
void AddDmigColumn(const Card& card, const std::string& path, DmigMatrix* m) {
  auto fail = [&](const std::string& what) { throw InputError(path + ":" + std::to_string(card.line) + ": " + what); };
  auto integer = [&](const std::string& text, const std::string& what) {
    const std::optional<long> v = Integer(text);
    if (!v) fail("'" + text + "' (" + what + ") is not an integer");
    return *v;
  };
  auto component = [&](const std::string& text, long grid) {
    const long c = text.empty() ? 0 : integer(text, "a component");
    if (c < 1 || c > 6) {
      fail("component '" + text + "' of point " + std::to_string(grid) +
           " is not 1..6: scalar and extra points have no place on a body (leave them out of the export)");
    }
    return int(c - 1);
  };
  const std::vector<std::string>& f = card.fields;
  const long gj = integer(f[1], "the column's grid GJ");
  const int cj = component(f[2], gj);
  for (size_t k = 4; k + 2 < f.size(); k += 4) {
    const std::string &g = f[k], &c = f[k + 1], &a = f[k + 2];
    if (g.empty() && c.empty() && a.empty()) continue;  // the blank fields of a short line
    const long gi = integer(g, "a row's grid");
    const int ci = component(c, gi);
    const std::optional<double> v = FortranReal(a);
    if (!v) {
      fail("'" + a + "' is not a finite number (DMIG " + m->name + " column " + std::to_string(gj) + " row " + g + ")");
    }
    m->entries.push_back({gi, ci, gj, cj, *v, card.line});
  }
}

// Every DMIG matrix of a file, in the order of their headers.
std::vector<DmigMatrix> ReadDmigFile(const std::string& path) {
  LineReader r(path, "matrix file");
  std::vector<DmigMatrix> matrices;
  std::map<std::string, size_t> index;
  for (const Card& card : DmigCards(&r)) {
    auto fail = [&](const std::string& what) {
      throw InputError(path + ":" + std::to_string(card.line) + ": " + what);
    };
    const std::vector<std::string>& f = card.fields;
    const std::string name = UpperCase(f[0]);
    if (name.empty()) fail("DMIG without a matrix name");
    if (f[1] == "0") {  // header: NAME 0 IFO TIN TOUT POLAR - NCOL
      if (index.count(name)) fail("DMIG " + name + " has a second header");
      if (f[2] != "1" && f[2] != "6")
        fail("DMIG " + name + " has IFO '" + f[2] + "': a stiffness or mass is square (1) or symmetric (6)");
      if (f[3] != "1" && f[3] != "2")
        fail("DMIG " + name + " has TIN '" + f[3] + "': only real matrices (1, 2) are read, not complex ones");
      index[name] = matrices.size();
      matrices.push_back({name, {}});
      continue;
    }
    auto it = index.find(name);
    if (it == index.end()) fail("DMIG " + name + " has a column before its header (NAME, 0, IFO, TIN)");
    AddDmigColumn(card, path, &matrices[it->second]);
  }
  return matrices;
}

// The stiffness (`letter` K) or mass (M) of a DMIG file: its only matrix, or the only one whose
// name starts with the letter (KAAX, MAAX as PARAM,EXTOUT,DMIGPCH names them).
const DmigMatrix& PickDmig(const std::vector<DmigMatrix>& matrices, const std::string& path, char letter,
                           const std::string& what) {
  if (matrices.size() == 1) return matrices.front();
  std::string names;
  const DmigMatrix* pick = nullptr;
  int count = 0;
  for (const DmigMatrix& m : matrices) {
    names += (names.empty() ? "" : ", ") + m.name;
    if (!m.name.empty() && m.name[0] == letter) {
      pick = &m;
      ++count;
    }
  }
  if (count != 1) {
    throw InputError(path + ": " + (matrices.empty() ? std::string("no DMIG matrix") : "DMIG matrices " + names) +
                     ": expected one " + what + " matrix (the file's only one, or the only one named " + letter +
                     "...)");
  }
  return *pick;
}

// The mapping file HBMAT writes: a header line, then "equation node label" per row.
void ReadAnsysMapping(const std::string& path, ImportedMatrices* out) {
  static const std::map<std::string, int> kLabels = {{"UX", 0},   {"UY", 1},   {"UZ", 2},
                                                     {"ROTX", 3}, {"ROTY", 4}, {"ROTZ", 5}};
  LineReader r(path, "DOF mapping file");
  std::string line;
  while (r.Next(&line, "!")) {
    const std::vector<std::string_view> f = Fields(line);
    if (!f.empty() && !std::isdigit(static_cast<unsigned char>(f[0][0])))
      continue;  // the header ("Matrix Eqn Node DOF")
    if (f.size() != 3) r.Fail("expected 'equation node label', got '" + line + "'");
    const long equation = IntegerField(r, f[0]), node = IntegerField(r, f[1]);
    if (equation != long(out->node.size()) + 1)
      r.Fail("equation " + std::to_string(equation) + " where " + std::to_string(out->node.size() + 1) + " comes next");
    auto it = kLabels.find(UpperCase(f[2]));
    if (it == kLabels.end()) {
      r.Fail("DOF label '" + std::string(f[2]) +
             "' is not UX, UY, UZ, ROTX, ROTY or ROTZ (warping, pressure, temperature and Lagrange multipliers have "
             "no place on a body)");
    }
    out->node.push_back(node);
    out->component.push_back(it->second);
  }
  if (out->node.empty()) throw InputError(path + ": no equations");
}

// One Fortran edit descriptor of a Harwell-Boeing header: (8I10), (1P,4E20.12), (3D25.16): items
// per line and their width.
std::pair<int, int> FortranLayout(const LineReader& r, std::string_view format) {
  std::string f = UpperCase(TrimBlanks(format));
  f.erase(std::remove_if(f.begin(), f.end(), [](char c) { return c == '(' || c == ')' || c == ' '; }), f.end());
  const size_t p = f.find('P');  // a scale factor (1P,) changes nothing on input with exponents
  if (p != std::string::npos) f = f.substr(f[p + 1] == ',' ? p + 2 : p + 1);
  size_t letter = 0;
  while (letter < f.size() && std::isdigit(static_cast<unsigned char>(f[letter]))) ++letter;
  if (letter >= f.size() || std::string("IEDFG").find(f[letter]) == std::string::npos)
    r.Fail("Fortran format '" + std::string(format) + "' is not nIw, nEw.d, nDw.d, nFw.d or nGw.d");
  const int count = letter == 0 ? 1 : std::atoi(f.substr(0, letter).c_str());
  const int width = std::atoi(f.substr(letter + 1).c_str());
  if (count < 1 || width < 1 || count > 1000 || width > 100) r.Fail("Fortran format '" + std::string(format) + "'");
  return {count, width};
}

// `n` fixed-width items of a Harwell-Boeing block, read line by line as its format lays them out.
std::vector<std::string> FortranItems(LineReader* r, std::pair<int, int> layout, long n, const std::string& what) {
  std::vector<std::string> items;
  std::string line;
  while (long(items.size()) < n) {
    if (!r->Next(&line, "")) r->Fail("the file ends in the " + what + " after " + std::to_string(items.size()));
    for (int k = 0; k < layout.first && long(items.size()) < n; ++k) {
      const size_t start = size_t(k) * size_t(layout.second);
      if (start >= line.size()) break;
      items.emplace_back(TrimBlanks(std::string_view(line).substr(start, size_t(layout.second))));
    }
  }
  return items;
}

// A Harwell-Boeing file (RSA: the lower triangle by columns; RUA: all of it) with n rows.
void ReadHarwellBoeing(const std::string& path, long n, const std::string& dofs, std::vector<MatrixEntry>* entries) {
  LineReader r(path, "matrix file");
  std::string line, title;
  if (!r.Next(&title, "") || !r.Next(&line, "")) r.Fail("not a Harwell-Boeing file (no header)");
  const std::vector<std::string_view> cards = Fields(line);
  if (cards.size() < 4) r.Fail("expected 'TOTCRD PTRCRD INDCRD VALCRD [RHSCRD]', got '" + line + "'");
  const long rhs_cards = cards.size() > 4 ? IntegerField(r, cards[4]) : 0;
  if (!r.Next(&line, "")) r.Fail("no matrix type line");
  const std::string type = UpperCase(line.substr(0, std::min<size_t>(3, line.size())));
  const std::string size_text = line.size() > 3 ? line.substr(3) : std::string();  // the views below point into it
  const std::vector<std::string_view> sizes = Fields(size_text);
  if (type != "RSA" && type != "RUA")
    r.Fail("matrix type '" + type +
           "': a real assembled matrix (RSA or RUA) is read, not complex, pattern or elemental");
  if (sizes.size() < 3) r.Fail("expected 'NROW NCOL NNZERO', got '" + line + "'");
  const long rows = IntegerField(r, sizes[0]), cols = IntegerField(r, sizes[1]), nnz = IntegerField(r, sizes[2]);
  if (rows != n || cols != n)
    r.Fail("the matrix is " + std::to_string(rows) + " x " + std::to_string(cols) + " but " + dofs + " maps " +
           std::to_string(n) + " equations");
  if (nnz < 0 || nnz > rows * (rows + 1)) r.Fail("NNZERO " + std::to_string(nnz) + " does not fit the size");
  if (!r.Next(&line, "")) r.Fail("no format line");
  line.resize(std::max<size_t>(line.size(), 72), ' ');
  const auto pointer_layout = FortranLayout(r, line.substr(0, 16));
  const auto index_layout = FortranLayout(r, line.substr(16, 16));
  const auto value_layout = FortranLayout(r, line.substr(32, 20));
  if (rhs_cards > 0 && !r.Next(&line, "")) r.Fail("no right-hand side line");
  const std::vector<std::string> pointers = FortranItems(&r, pointer_layout, n + 1, "column pointers");
  const std::vector<std::string> indices = FortranItems(&r, index_layout, nnz, "row indices");
  const long values_line = r.number() + 1;
  const std::vector<std::string> values = FortranItems(&r, value_layout, nnz, "values");
  long previous = 1;
  for (long j = 0; j < n; ++j) {
    const long begin = IntegerField(r, pointers[size_t(j)]), end = IntegerField(r, pointers[size_t(j + 1)]);
    if (begin != previous || end < begin || end > nnz + 1)
      r.Fail("column pointer " + std::to_string(j + 1) + " is not increasing within 1.." + std::to_string(nnz + 1));
    previous = end;
    for (long q = begin - 1; q < end - 1; ++q) {
      const long i = IntegerField(r, indices[size_t(q)]);
      if (i < 1 || i > n) r.Fail("row index " + std::to_string(i) + " outside 1.." + std::to_string(n));
      const std::optional<double> v = FortranReal(values[size_t(q)]);
      if (!v) r.Fail("value '" + values[size_t(q)] + "' is not a finite number");
      entries->push_back({i - 1, j, *v, values_line});
    }
  }
  if (previous != nnz + 1) r.Fail("the column pointers end at " + std::to_string(previous) + ", not NNZERO + 1");
}

}  // namespace

void ReadNastranDmig(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                     std::vector<MatrixEntry>* m) {
  const std::vector<DmigMatrix> k_file = ReadDmigFile(spec.stiffness);
  const std::vector<DmigMatrix> m_file = spec.mass == spec.stiffness ? k_file : ReadDmigFile(spec.mass);
  const DmigMatrix& K = PickDmig(k_file, spec.stiffness, 'K', "stiffness");
  const DmigMatrix& M = PickDmig(m_file, spec.mass, 'M', "mass");
  if (&K == &M || (spec.mass == spec.stiffness && K.name == M.name))
    throw InputError(spec.stiffness + ": the stiffness and the mass are the same DMIG matrix " + K.name);
  IndexLabelledEntries(K.entries, M.entries, out, k, m);
}

void ReadAnsys(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
               std::vector<MatrixEntry>* m) {
  ReadAnsysMapping(spec.dofs, out);
  const long n = long(out->node.size());
  for (auto [path, entries] : {std::pair{&spec.stiffness, k}, std::pair{&spec.mass, m}}) {
    LineReader r(*path, "matrix file");
    std::string first;
    if (!r.Next(&first, "")) r.Fail("empty file");
    if (first.rfind("%%MatrixMarket", 0) == 0 || first.rfind("%%matrixmarket", 0) == 0) {
      ReadMatrixMarketFile(*path, n, spec.dofs, entries);
    } else {
      ReadHarwellBoeing(*path, n, spec.dofs, entries);
    }
  }
}

}  // namespace femb
