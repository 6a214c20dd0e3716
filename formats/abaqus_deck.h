// Abaqus input decks (.inp) as Abaqus/CAE writes them: parts (*Part ... *End Part) placed by
// instances of an assembly (*Assembly, *Instance with its translation and rotation lines), or a
// flat deck (*Node and *Element at the top level, as CalculiX and older decks have it). What is
// read: nodes, elements (their type and nodes), node and element sets (data lines of labels or
// set names, GENERATE ranges, INSTANCE= and "instance.label" references in the assembly). The
// model data ends at the first *Step. Keywords and names are case-insensitive (Abaqus rules).
//
// The equations of Abaqus' FORMAT=COORDINATE matrix output are numbered from this: instance by
// instance in the order of the *Instance lines, each instance's nodes by ascending label, and at
// each node the degrees of freedom its elements use, ascending (1..6 = u_x, u_y, u_z, theta_x,
// theta_y, theta_z). A node of no element has none.
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

namespace femb {

/// An element as the deck gives it: its type in upper case and its nodes' labels.
struct AbaqusElement {
  std::string type;
  long label = 0;
  std::vector<long> nodes;
};

/// One instance of a part, placed in the assembly (or the whole of a flat deck).
struct AbaqusMesh {
  std::string name;          ///< the instance's name as written ("" for a flat deck)
  std::vector<long> labels;  ///< node labels, ascending
  Eigen::MatrixXd nodes;     ///< n x 3, placed: x = R x_part + t
  std::vector<AbaqusElement> elements;
  std::vector<long> element_lines;  ///< the deck line of each element's *Element keyword
  /// Node sets (named as first written) as 0-based indices into `labels`: *Nset of the part and of the
  /// assembly for this instance, and the nodes of every named element set.
  std::map<std::string, std::vector<int>> node_sets;
};

/// A deck: its meshes, one per instance (a flat deck: one, named "").
struct AbaqusDeck {
  std::string path;
  bool assembly = false;    ///< the deck has *Instance lines
  long assembly_nodes = 0;  ///< nodes defined at the assembly level (reference points): in no mesh
  std::vector<AbaqusMesh> instances;
};

/// Reads a deck. Throws InputError "PATH:LINE: ..." for: an unreadable file, a keyword line
/// without its required parameter (*Part name, *Instance part, *Element type), a data line that
/// is not numbers where numbers belong, an element or set naming a node or set the part does not
/// have, an *Include (not read: inline it), an instance of an unknown part, a deck without nodes.
AbaqusDeck ReadAbaqusDeck(const std::string& path);

/// Whether the deck places parts by *Instance lines (a quick scan up to the first *Step).
/// Throws InputError when the file cannot be opened.
bool HasInstances(const std::string& path);

/// The index of the instance named `name` (case-insensitive); with `name` empty the deck must
/// have one instance. Throws InputError "`where`: ..." naming the deck and its instances.
int PickInstance(const AbaqusDeck& deck, const std::string& name, const std::string& where);

/// The degrees of freedom (bit c = component c, 0..5) an element type uses at its nodes, or 0
/// for a type whose equations cannot be derived here (hybrid elements and other types with
/// Abaqus internal nodes, five-DOF shells, planar, axisymmetric, connector and spring elements).
unsigned ElementDofMask(const std::string& type);

/// One equation of Abaqus' coordinate matrix output: instance, node label, component 0..5.
struct AbaqusEquation {
  int instance;
  long node;
  int component;
};

/// Every equation of the deck's model in Abaqus' order (see the file comment). Throws InputError
/// "PATH:LINE: ..." at the first element whose type ElementDofMask cannot place.
std::vector<AbaqusEquation> CoordinateEquations(const AbaqusDeck& deck);

}  // namespace femb
