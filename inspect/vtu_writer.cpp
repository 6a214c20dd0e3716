#include "inspect/vtu_writer.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "formats/input_error.h"
#include "formats/vtk_cells.h"

namespace femb {

int WriteModeShapesVtu(const Superelement& se, const std::string& directory) {
  if (!se.visualization) {
    throw InputError(se.name + ": no mesh and mode shapes stored in the file (reduce with reduction.keep_mesh: true)");
  }
  const Visualization& v = *se.visualization;
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw InputError(directory + ": cannot create folder (" + ec.message() + ")");
  const Eigen::MatrixXi cells = ToVtkOrder(v.cell_type, v.cells);
  const int type = VtkCellType(v.cell_type);
  const long n = v.nodes.rows();
  for (int i = 0; i < se.n_reduced_dofs(); ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "%s_%03d.vtu", se.name.c_str(), i);
    const std::string path = (std::filesystem::path(directory) / name).string();
    const std::string tmp = path + ".tmp." + std::to_string(::getpid());
    {
      std::ofstream out(tmp);
      if (!out) throw InputError(tmp + ": cannot write");
      out.precision(12);
      out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
             "byte_order=\"LittleEndian\">\n"
          << "<!-- " << ReducedCoordinateLabel(se, i) << " -->\n<UnstructuredGrid>\n"
          << "<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << cells.rows() << "\">\n"
          << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
      for (long p = 0; p < n; ++p) out << v.nodes(p, 0) << " " << v.nodes(p, 1) << " " << v.nodes(p, 2) << "\n";
      out << "</DataArray></Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
      for (long c = 0; c < cells.rows(); ++c) {
        for (long a = 0; a < cells.cols(); ++a) out << cells(c, a) << " ";
        out << "\n";
      }
      out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
      for (long c = 0; c < cells.rows(); ++c) out << (c + 1) * cells.cols() << " ";
      out << "\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
      for (long c = 0; c < cells.rows(); ++c) out << type << " ";
      out << "\n</DataArray>\n</Cells>\n<PointData Vectors=\"displacement\">\n"
          << "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n";
      for (long p = 0; p < n; ++p) {
        for (int d = 0; d < 3; ++d) out << v.shapes(v.dofs_per_node * p + d, i) << (d < 2 ? " " : "\n");
      }
      out << "</DataArray>\n";
      if (v.dofs_per_node == 6) {
        out << "<DataArray type=\"Float64\" Name=\"rotation\" NumberOfComponents=\"3\" format=\"ascii\">\n";
        for (long p = 0; p < n; ++p) {
          for (int d = 0; d < 3; ++d) out << v.shapes(6 * p + 3 + d, i) << (d < 2 ? " " : "\n");
        }
        out << "</DataArray>\n";
      }
      if (se.stress) {
        // The mode's stress per unit coordinate (femb-reduce's modal stresses): von Mises and the
        // tensor, VTK's symmetric order xx yy zz xy yz xz (ParaView shows it as a tensor).
        Eigen::VectorXd unit = Eigen::VectorXd::Zero(se.n_reduced_dofs()), von_mises;
        unit[i] = 1.0;
        Eigen::MatrixXd stress;
        NodeStresses(*se.stress, unit, n, &stress, &von_mises);
        out << "<DataArray type=\"Float64\" Name=\"von_mises\" format=\"ascii\">\n";
        for (long p = 0; p < n; ++p) out << von_mises[p] << "\n";
        out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"stress\" NumberOfComponents=\"6\" format=\"ascii\">\n";
        for (long p = 0; p < n; ++p) {
          out << stress(p, 0) << " " << stress(p, 1) << " " << stress(p, 2) << " " << stress(p, 5) << " "
              << stress(p, 3) << " " << stress(p, 4) << "\n";
        }
        out << "</DataArray>\n";
      }
      out << "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
      if (!out) throw InputError(tmp + ": write failed");
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw InputError(path + ": cannot rename into place (" + ec.message() + ")");
  }
  return se.n_reduced_dofs();
}

}  // namespace femb
