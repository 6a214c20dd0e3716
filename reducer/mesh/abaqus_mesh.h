// The mesh of one instance of an Abaqus deck (formats/abaqus_deck.h) as a ForeignMesh: the cells
// of the highest dimension the instance has, in gmsh node order, for imported parts whose deck
// places parts by instances (meshio reads such a deck without the instances' placement and
// cannot tell two instances apart).
#pragma once

#include <string>

#include "formats/abaqus_deck.h"
#include "reducer/mesh/meshio_import.h"

namespace femb {

/// Volume cells (C3D4, C3D10, C3D8, C3D20 and their variants; one type), else surface cells
/// (S3, S4, STRI65, S8R, M3D*: a mix drawn as tri3 through the corners), else line cells (B31,
/// B32, B33, T3D2, T3D3: the end nodes). Node sets as the deck's. Throws InputError "`where`:
/// ..." for mixed volume types and an instance without cells femb can draw.
ForeignMesh ForeignMeshOf(const AbaqusMesh& mesh, const std::string& where);

/// An imported part's geometry: for an Abaqus deck with instances, the instance named
/// `instance` (or the only one) read by femb; any other file (flat decks too) through meshio.
ForeignMesh ReadImportedGeometry(const std::string& path, const std::string& instance, const std::string& where);

}  // namespace femb
