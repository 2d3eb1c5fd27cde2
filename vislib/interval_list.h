// interval_list.h: per-pixel depth compositing of coverage intervals (math note §7; the paper's
// DepthComposite, Alg. 1 line 9, with the corrections of the note).
//
// A pixel's list is a sorted vector of disjoint pieces [t0, t1) of the segment parameter, each
// holding the id of the front-most triangle there and that triangle's depth function. Inserting a
// triangle's coverage interval keeps the lower envelope: closer intervals split farther ones,
// interpenetrating triangles split at the exact depth crossing, depth ties go to the lower id.
// The resulting list depends only on the set of inserted intervals, never on their order.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

namespace vislib {

// Depth along the pixel ray (view-space depth lambda, scene units) as a function of t.
// Static triangles: lambda(t) = (n0 - n1 t) / dn, linear in t (math note §2.4, (I3)), with
// n0 = n.(a - v0), n1 = n.Delta, dn = d.n. Kept as the three numbers (not a slope and offset) so
// that depth crossings come from exact-as-possible products (§3.4: P = N_i D_j - N_j D_i).
struct LinearDepth {
  double n0 = 0, n1 = 0, dn = 1;
  double at(double t) const { return (n0 - n1 * t) / dn; }
};

struct Piece {
  double t0 = 0, t1 = 0;  // 0 <= t0 < t1 <= 1
  uint32_t id = 0;        // triangle id
  LinearDepth depth;
};

using PieceList = std::vector<Piece>;

// Inserts the coverage interval `p` (p.t0 < p.t1) into `list` (sorted, disjoint, merged).
// Returns false when the list is unchanged (p is hidden wherever it overlaps the list).
// Not thread-safe for the same list; lists are per pixel.
bool insert_piece(PieceList& list, const Piece& p);

// The piece covering t (t0 <= t < t1), if any.
std::optional<Piece> lookup(const PieceList& list, double t);

// True when the pieces cover [0, 1] without gap.
bool covers_segment(const PieceList& list);

// Largest depth over all pieces (at their ends); -inf for an empty list.
double farthest_depth(const PieceList& list);

// Checks the invariants of §7 (sorted, disjoint, 0 <= t0 < t1 <= 1, touching same-id pieces
// merged). For tests and debug builds.
bool is_valid(const PieceList& list);

}  // namespace vislib
