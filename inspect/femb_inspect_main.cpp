// femb-inspect: show and check what a superelement file holds.
#include <cstdio>
#include <iostream>
#include <string>

#include "formats/input_error.h"
#include "formats/matrix_text.h"
#include "formats/superelement_file.h"
#include "inspect/report.h"
#include "inspect/superelement_checks.h"

namespace {

constexpr const char* kUsage = R"(usage: femb-inspect FILE.h5 [--json] [--check] [--dump K|M|PhiCB [--format mtx|csv]]

Shows a superelement file: units, interfaces, floating frame, mass properties, the 6x6 rigid-body
mass matrix, a label for every reduced coordinate, reduced vs full free-free frequencies, checks.

options:
  --json                one JSON object instead of the text summary
  --check               exit 1 when a check fails (K, M symmetric, M positive definite,
                        exactly 6 rigid-body modes, Phi_CB Phi_rig0 = 1)
  --dump K|M|PhiCB      print that matrix to stdout (full precision)
  --format mtx|csv      Matrix Market (default) or CSV for --dump
  -h, --help            this text

exit codes: 0 success, 1 a check failed (with --check), 2 bad input or unreadable file.
)";

}  // namespace

int main(int argc, char** argv) {
  std::string path, dump, format = "mtx";
  bool json = false, check = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "femb-inspect: %s needs a value (see --help)\n", flag);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--json") {
      json = true;
    } else if (a == "--check") {
      check = true;
    } else if (a == "--dump") {
      dump = value("--dump");
    } else if (a == "--format") {
      format = value("--format");
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "femb-inspect: unknown option '%s' (see --help)\n", a.c_str());
      return 2;
    } else if (path.empty()) {
      path = a;
    } else {
      std::fprintf(stderr, "femb-inspect: more than one file given\n");
      return 2;
    }
  }
  if (path.empty()) {
    std::fprintf(stderr, "femb-inspect: no superelement file given\n%s", kUsage);
    return 2;
  }
  if (!dump.empty() && dump != "K" && dump != "M" && dump != "PhiCB") {
    std::fprintf(stderr, "femb-inspect: --dump takes K, M or PhiCB, got '%s'\n", dump.c_str());
    return 2;
  }
  if (format != "mtx" && format != "csv") {
    std::fprintf(stderr, "femb-inspect: --format takes mtx or csv, got '%s'\n", format.c_str());
    return 2;
  }
  try {
    femb::SuperelementReadOptions options;
    options.visualization = false;
    const femb::Superelement se = femb::ReadSuperelementFile(path, options);
    if (!dump.empty()) {
      const Eigen::MatrixXd& A = dump == "K" ? se.K : dump == "M" ? se.M : se.floating_frame.Phi_CB;
      if (format == "mtx") {
        femb::WriteMatrixMarket(std::cout, A, se.name + " " + dump + " from " + path);
      } else {
        femb::WriteCsv(std::cout, A);
      }
      return 0;
    }
    const femb::SuperelementAnalysis analysis = femb::AnalyzeSuperelement(se);
    if (json) {
      std::cout << femb::JsonSummary(se, analysis).dump(2) << "\n";
    } else {
      std::cout << femb::TextSummary(se, analysis, path);
    }
    if (check && !analysis.all_ok()) {
      for (const auto& c : analysis.checks) {
        if (!c.ok) std::fprintf(stderr, "femb-inspect: %s: check %s failed: %s\n", path.c_str(), c.name.c_str(), c.detail.c_str());
      }
      return 1;
    }
    return 0;
  } catch (const femb::InputError& e) {
    std::fprintf(stderr, "femb-inspect: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "femb-inspect: internal error: %s\n", e.what());
    return 1;
  }
}
