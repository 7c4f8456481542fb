// Unambiguous repairs of real-world skins, reported, never silent.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/fdp.h"
#include "core/scene.h"

namespace afmb {

// Welds vertices with bit-identical positions that share a zero-area triangle
// (an exporter's duplicate), rewriting the part's triangles to use the lower
// index, then drops the triangles left with a repeated index. Vertex indices
// do not change: a welded-away vertex stays in V, unreferenced, so FDP
// indices into the part stay valid. Everything else (slivers with distinct
// corners, non-manifold edges) is left for check_skin() to refuse. Appends one
// line per repair to `log`; returns the number of triangles dropped.
int repair_coincident_vertices(Scene &scene, int part, std::vector<std::string> *log);

// A skin part made of several pieces (a mesh exported as one object, its
// eyeballs, teeth and tongue inside the head's) is split into one part per
// piece, so that only the face's surface is simulated and the rest follows
// what it belongs to. Pieces are connected by shared triangles' corners and
// by vertices at bit-identical positions on open edges (a seam an exporter
// split stays one piece; closed pieces that touch, as teeth rows, do not
// join). The piece holding the part's FDP 2.1 keeps the part's name, kind,
// material and its unreferenced vertices; each other piece becomes a new part
// after it, named `<part>_<kind>` by the FDPs it holds (fdp_part_kind: 3.5
// eye_left, 3.6 eye_right, 6.x tongue, 9.8/9.10 teeth_upper, 9.9/9.11
// teeth_lower) with that kind; a piece holding none whose centre lies in
// the mouth (within a quarter of the mouth's width beyond its corners 2.4,
// 2.5, between the chin 2.1 and as far above the lip line 2.2, behind 2.2 by
// up to 1.5 mouth widths) is teeth_upper above the lip line and teeth_lower
// below it (teeth, gums or a tongue: each then moves with its bone); the
// rest `<part>_piece<N>` (N from 2, kind Other: it follows the head).
// Vertices keep their order within a piece; colours and texture corners go
// with them, and where the part knows its faces' materials (OBJ) each piece
// takes the one most of its triangles use (the eyes their own texture). The
// FDPs on the part are moved to their piece's part and vertex. Appends one line to `log`
// naming the pieces; returns how many parts were added (0: one piece, or no
// 2.1 on the part).
int split_skin_pieces(Scene &scene, int part, FdpSet &fdps, std::vector<std::string> *log);

// A closed mouth with no slit (a scan's lips are one surface: FDPs 2.2 and
// 2.3 on one vertex) cannot open: the jaw would stretch the lips like a
// membrane. So the skin is cut along the lip line: the shortest path over
// the skin's edges from the left corner 2.4 through 2.6, 2.2 (= 2.3), 2.7
// to the right corner 2.5 (each FDP on its upper-lip point where the lower
// one sits on another vertex). Each vertex inside the path gets a copy at
// its position, appended to the part (colours and per-vertex texture
// coordinates copied); the triangles below the line, about each such vertex,
// take the copy; the corners stay whole, as a slit ends there. 2.3, 2.8 and
// 2.9 move to the copies where they sat on the line. Leaves the part alone
// (returns 0) where 2.2 and 2.3 are different vertices, an FDP of the line is
// missing or off the part, or the line would run along the skin's edge or
// through one vertex twice; else appends one line to `log` and returns how
// many vertices were copied.
int cut_fused_lips(Scene &scene, int part, FdpSet &fdps, std::vector<std::string> *log);

// Closed surfaces that touch along a line (teeth rows) share, once welded,
// edges in four triangles. Around such an edge a -> b, each surface's two
// triangles bound its inside: going round the edge (right-handed about
// b - a), a triangle that runs the edge b -> a faces its inside ahead, one
// that runs it a -> b behind, so each b -> a triangle pairs with the next
// one round, which must run a -> b. The surfaces are the triangles joined
// through edges in two triangles and through these pairs; each vertex used
// by several surfaces gets one copy per surface after the first (appended
// to V). Left alone (returns 0) where an edge is in an odd number of
// triangles above one, or its triangles do not alternate round it: nothing
// tells the surfaces apart there, and check_skin() names it. Returns how
// many vertices were split. V #V x 3 (grows by the copies), F #F x 3
// (rewritten). The STL reader calls it on the triangles it has welded.
int split_touching_surfaces(Eigen::MatrixXd &V, Eigen::MatrixXi &F);

}  // namespace afmb
