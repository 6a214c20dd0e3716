// Foreign mesh formats (Abaqus .inp, Nastran .bdf, VTK/VTU, MED, ...) through meshio: the
// Python bridge formats/meshio_bridge.py (run with Debian's /usr/bin/python3) writes femb's
// plain-text mesh, read here. Named node sets: meshio's point sets and the nodes of its named
// cell sets.
#pragma once

#include <string>

#include "reducer/mesh/gmsh_mesher.h"

namespace femb {

/// true for extensions gmsh reads itself (.msh, .geo, .step, .stp, .brep).
bool IsGmshFile(const std::string& path);

/// Throws InputError for: python3 or meshio missing (with the apt-get line), an unreadable
/// file, no volume elements.
SolidMesh ImportWithMeshio(const std::string& path, const std::string& where);

}  // namespace femb
