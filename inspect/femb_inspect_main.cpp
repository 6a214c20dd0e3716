// femb-inspect: show and check what a superelement file holds.
#include <cstdio>
#include <iostream>
#include <string>

#include "formats/command_line.h"
#include "formats/input_error.h"
#include "formats/matrix_text.h"
#include "formats/superelement_file.h"
#include "inspect/mbdyn_export.h"
#include "inspect/report.h"
#include "inspect/superelement_checks.h"
#include "inspect/vtu_writer.h"

namespace {

constexpr const char* kUsage =
    R"(usage: femb-inspect FILE.h5 [--json] [--check] [--dump K|M|PhiCB [--format mtx|csv]] [--vtu DIR]
       femb-inspect FILE.h5 --export-mbdyn OUT.fem [--mbdyn-mesh]

Shows a superelement file: units, interfaces, floating frame, mass properties, the 6x6 rigid-body
mass matrix, a label for every reduced coordinate, reduced vs full free-free frequencies, checks.

options:
  --json                one JSON object instead of the text summary
  --check               exit 1 when a check fails (K, M symmetric, M positive definite,
                        exactly 6 rigid-body modes, Phi_CB Phi_rig0 = 1)
  --dump K|M|PhiCB      print that matrix to stdout (full precision)
  --format mtx|csv      Matrix Market (default) or CSV for --dump
  --vtu DIR             write every reduced coordinate's shape as DIR/<name>_<i>.vtu (ParaView;
                        needs the mesh in the file: reduction.keep_mesh)
  --export-mbdyn OUT    write MBDyn's modal element file (.fem): the modes relative to the
                        floating frame (MBDyn's modal node), their mass and stiffness, the
                        shapes at the interfaces (FEM nodes named as the interfaces), the
                        rigid-body inertia and the inertia invariants 3, 4, 5, 8, 9
  --mbdyn-mesh          with --export-mbdyn: every mesh node is a FEM node too (1..n)
  -h, --help            this text

exit codes: 0 success, 1 a check failed (with --check), 2 bad input or unreadable file.
)";

}  // namespace

int main(int argc, char** argv) {
  std::string dump, format = "mtx", vtu, mbdyn;
  bool json = false, check = false, mbdyn_mesh = false;
  femb::CommandLine cli("femb-inspect", kUsage, "superelement file");
  cli.Value({"--dump"}, [&](const std::string& v) { dump = v; });
  cli.Value({"--format"}, [&](const std::string& v) { format = v; });
  cli.Value({"--vtu"}, [&](const std::string& v) { vtu = v; });
  cli.Value({"--export-mbdyn"}, [&](const std::string& v) { mbdyn = v; });
  cli.Switch({"--mbdyn-mesh"}, [&] { mbdyn_mesh = true; });
  cli.Switch({"--json"}, [&] { json = true; });
  cli.Switch({"--check"}, [&] { check = true; });
  if (!cli.Parse(argc, argv)) return cli.exit_code();
  const std::string path = cli.input();
  try {
    femb::SuperelementReadOptions options;
    options.visualization = !vtu.empty() || mbdyn_mesh;
    options.stress = !vtu.empty();
    const femb::Superelement se = femb::ReadSuperelementFile(path, options);
    if (!mbdyn.empty()) {
      const femb::MbdynExport e = femb::WriteMbdynFem(se, mbdyn, mbdyn_mesh);
      std::printf("femb-inspect: wrote %s: %d modes at %d FEM nodes (interfaces:", mbdyn.c_str(), e.modes, e.nodes);
      for (const auto& node : se.interfaces) std::printf(" \"%s\"", node.name.c_str());
      std::printf(")%s; MBDyn's modal node is the floating frame (%s) at %g %g %g\n",
                  e.invariants ? ", inertia invariants 3, 4, 5, 8, 9" : "", se.floating_frame.type.c_str(),
                  se.floating_frame.origin.x(), se.floating_frame.origin.y(), se.floating_frame.origin.z());
      for (const std::string& note : e.notes) std::printf("femb-inspect: note: %s\n", note.c_str());
      return 0;
    }
    if (!vtu.empty()) {
      const int written = femb::WriteModeShapesVtu(se, vtu);
      std::printf("femb-inspect: wrote %d mode shapes to %s/%s_*.vtu\n", written, vtu.c_str(), se.name.c_str());
      return 0;
    }
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
        if (!c.ok)
          std::fprintf(stderr, "femb-inspect: %s: check %s failed: %s\n", path.c_str(), c.name.c_str(),
                       c.detail.c_str());
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
