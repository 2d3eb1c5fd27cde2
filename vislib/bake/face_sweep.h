// face_sweep.h: a face of a view region swept by parallel chords, evenly or where the visible set
// changes.
//
// What an eye inside a convex region that holds no geometry sees is seen from the region's
// boundary, and the boundary's faces are sampled by chords: segments across a face, parallel to
// one direction. The even sweep places them at equal steps; the adaptive sweep (docs/quake.md
// "Chords where the set changes") starts coarse and inserts a chord between two neighbours only
// while the new chord sees ids that neither neighbour sees, down to a floor spacing: a flat wall
// costs a few chords, a doorway as many as it needs.
#pragma once

#include <cmath>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/scene.h"

namespace vislib {

// A convex planar face (its vertices in order, any winding) swept by the chords
// face ∩ {x : dot(across, x) = h} for lo < h < hi, where [lo, hi] is the face's extent along the
// unit vector `across` (which lies in the face's plane, perpendicular to the chords, whose unit
// direction is `along`).
struct FaceSweep {
  std::vector<Vec3> face;
  Vec3 along, across;
  double lo = 0, hi = 0;
  // The directions its chords count (Segment::side_normal and side; zero: all): a portal's.
  Vec3 side_normal{0, 0, 0};
  int side = 0;
  // The chords are cut to t_lo <= dot(along, x) <= t_hi: a strip of the face (sweep_strips). The
  // face's edges stay its base's (the adaptive sweep's extreme positions).
  double t_lo = -INFINITY, t_hi = INFINITY;
  // A crossed family's sweep (crossed_sweep): refined down to AdaptiveSpacing::crossed_floor.
  bool crossed = false;
};

// Chords shorter than this (scene units) are points and are not run (a chord at a face's vertex);
// the faces of BSP leaf volumes agree to about 1e-12 units.
constexpr double kSweepMinChord = 1e-6;

// The sweep of `face` (convex, planar, normal `normal`) by chords parallel to its longest edge
// (the first such edge in vertex order); nothing when that edge or the face's width is shorter
// than `min_length`.
std::optional<FaceSweep> face_sweep_of(const std::vector<Vec3>& face, Vec3 normal,
                                       double min_length);

// The chord of `sweep` at h (lo <= h <= hi): from the face's boundary point with the smallest to
// the one with the largest coordinate along the chords, with the sweep's side_normal and side.
// Nothing when it is shorter than `min_length` (at a vertex of the face, say).
std::optional<Segment> face_chord(const FaceSweep& sweep, double h, double min_length);

// `sweep` cut across its chords into strips of equal length along them, at most `length` long
// (length > 0): each strip's chords are the pieces of the face's chords over its stretch, the
// first and the last strips open-ended (so that together they cover every chord whole, each piece
// ending where the next begins). One strip, `sweep` itself, when the face is not longer.
std::vector<FaceSweep> sweep_strips(const FaceSweep& sweep, double length);

// The sweep of `sweep`'s face by chords perpendicular to its chords (along becomes across), over
// the whole face, with the same side_normal and side, marked `crossed`. What a polygon's points
// see in one direction d is seen from a patch of it (the visible parts' shadow along d); a patch
// thin across one family's chords, a slit's, is long along them, and the other family crosses it.
FaceSweep crossed_sweep(const FaceSweep& sweep);

// The even sweep: chords at h = lo + k (hi - lo) / n, k = 1 .. n - 1, with n = ceil((hi - lo) /
// spacing) (at most `spacing` apart), in increasing k; none when the width is not larger than
// spacing. `spacing` > 0.
std::vector<Segment> even_chords(const FaceSweep& sweep, double spacing, double min_length);

// The margin of chord_tiles_toward in the bake (tiles): what a gap newly opens is seen beside the
// ids that showed it (the gap's other side, its neighbours). With tiles of 32 pixels, margin 0
// cost lqdm1 whole about 0.9 of margin 1's CPU for 9 and 120 sampled miss rays against 8 and 98
// (4 and 32 eyes a leaf), and e2m3's 47-leaf sample 0.88 for 16 against 7 (docs/quake.md).
constexpr int kChordTileMargin = 1;

// The default tile side of those masks and of the runs they mask (pixels; AdaptiveSpacing::
// tile_size, RegionOptions::segment_tile_mask_size): the margin is one such tile, and a masked run
// computes whole tiles, so finer tiles keep a run to what it looks for. The whole cubes keep the
// kernel's tiles (kStaticTileSize), which are faster for them. Against 32 (measured in
// alternating pairs): 0.93 of lqdm1 whole's CPU for 9 and 104 sampled miss rays against 8 and 98,
// 0.92 and 0.85 of e2m3's 47-leaf and e1m2's 63-leaf samples' for the same 7 and 18
// (docs/quake.md).
constexpr int kChordTileSize = 16;

// What a chord inserted below a probe that saw new ids computes:
// - All: its whole cube, as every other chord;
// - New: the tiles of one cube face where those ids can appear, or its whole cube when one of
//   them is seen across a face's edge;
// - NewEveryFace: the tiles on every cube face where they can appear (chord_tiles_toward).
enum class ChordTiles { All, New, NewEveryFace };

// The name of each value in `pvs bake --chord-tiles` and in a bake's metadata ("all", "new",
// "new-every-face"), every name in the enum's order, and the value of a name (std::nullopt for
// any other string).
const char* chord_tiles_name(ChordTiles tiles);
std::vector<std::string_view> chord_tiles_names();
std::optional<ChordTiles> chord_tiles_named(std::string_view name);

// The spacings of the adaptive sweep (the sweeps' units): the first chords lie at most `coarse`
// apart (the even sweep's positions); a chord is inserted midway between two neighbours (a face's
// own extreme positions count as neighbours that see its base, below) whose distance is larger
// than `floor`, and kept on the grid of halvings, while the last one inserted there saw an id
// that neither neighbour saw. 0 < floor <= coarse. With `piece` > 0 each swept face is first cut
// into strips at most `piece` long along its chords (sweep_strips), each refined on its own, so a
// long chord's probes go on only over the stretches where new ids are seen (0: whole chords).
// With `tiles` other than All a chord inserted below a probe that saw new ids looks only toward
// those (the bake runs it on the cube tiles of `tile_size` pixels where they can appear,
// chord_tiles_toward); the sweep itself only hands each chord its parent's new ids (ChordRound).
// With `crossed` each face is also swept by chords perpendicular to the first (crossed_sweep),
// refined on their own down to `crossed_floor` (floor <= crossed_floor <= coarse; 0: `floor`): a
// second family of sweeps over the same faces, with the same base. The patches it is there for
// are long across its chords, so it can stop coarser than the first family.
// With `new_to_family` a probe's ids count as new only when its family has not seen them either:
// the sweeps over one face with one side and one direction of chords (a face's strips; its
// crossed sweep is another family), from their base and every chord of an earlier round. An id
// the family holds already adds nothing to the set, wherever it was seen; the chords inserted
// below look toward the ids that are new so.
struct AdaptiveSpacing {
  double coarse = 64;
  double floor = 4;
  double piece = 0;
  ChordTiles tiles = ChordTiles::All;
  int tile_size = kChordTileSize;
  bool crossed = false;
  double crossed_floor = 0;
  bool new_to_family = false;
  // The spacings are in range: 0 < floor <= coarse, and crossed_floor 0 or between them.
  bool valid() const {
    return floor > 0 && floor <= coarse &&
           (crossed_floor == 0 || (floor <= crossed_floor && crossed_floor <= coarse));
  }
  // The crossed family's floor: crossed_floor when set, else floor.
  double crossed_floor_or_floor() const { return crossed_floor > 0 ? crossed_floor : floor; }
  // The floor of `sweep`'s chords: the crossed family's for a crossed sweep, else floor.
  double floor_of(const FaceSweep& sweep) const {
    return sweep.crossed ? crossed_floor_or_floor() : floor;
  }
};

// Sees one round of chords: `chords` (run as one group of segments), `sweep_of` the index of the
// sweep each lies on, and `fresh` for each chord the sorted ids its parent probe saw that
// neither of the parent's neighbours saw (the reason the chord is there; empty for the coarse
// grid and the first probe between two coarse positions), and returns for each chord the sorted
// ids it saw (any sorted id space does: triangles, then spheres offset by the triangle count,
// say). Called once per round, in round order.
using ChordRound = std::function<std::vector<std::vector<uint32_t>>(
    const std::vector<Segment>& chords, const std::vector<size_t>& sweep_of,
    const std::vector<std::vector<uint32_t>>& fresh)>;

// What an adaptive sweep is expected to run, for progress and its ETA only (the chords run do
// not depend on it). An open interval of width `width` gets one probe and, with probability
// `refine` (in [0, 1]: the share of probes that see a new id), its two halves, each probed in
// turn while wider than `floor` (> 0). Positions, not runs: a chord too short to run counts too.
double expected_probes(double width, double floor, double refine);

// The refine rate assumed before any probe has been judged: open leaves refine nearly every
// probe, flat walls almost none.
constexpr double kRefinePrior = 0.5;

// The positions adaptive_sweep(sweeps, spacing, ...) is expected to probe in all, with every
// interval refined at rate `refine`: the coarse grid's, then expected_probes of each coarse
// interval wider than the floor.
double expected_adaptive_probes(const std::vector<FaceSweep>& sweeps,
                                const AdaptiveSpacing& spacing, double refine);

// Told before each round: the chords run so far and the positions expected in all (those run,
// this round's, and the later rounds' at the refine rate of the last round judged, or
// kRefinePrior before round 1 is judged).
using SweepEstimate = std::function<void(size_t run, double expected)>;

// The tiles of a world-aligned cube (SegmentOptions::tile_mask, resolution `n`, tiles of
// `tile_size` pixels) in which a triangle of `tris` (of `scene` in key state `state`) can cover
// a pixel's centre seen from an eye of `chord`, one pixel of slack around, grown by `margin`
// tiles each way; std::nullopt (the whole cube) when `tris` is empty and:
// - one face (`every_face` false): when a corner of one of them does not lie in front of the same
//   face from both of the chord's ends. A point's image moves along a line while the eye moves
//   along the chord, so the box of its images from the ends holds every other, and a face's
//   frustum is convex.
// - every face (`every_face`): on each face where one can appear; the whole cube only when one
//   meets the chord (its directions then surround the eyes). The directions from the chord's eyes
//   to a triangle's points are the cone over the convex hull of its corners minus the chord's
//   ends; a face's part of it is the cone over the hull's part inside the face's frustum, whose
//   image the tiles hold.
// Conservative either way.
std::optional<std::vector<uint8_t>> chord_tiles_toward(const Scene& scene, size_t state,
                                                       const Segment& chord,
                                                       const std::vector<uint32_t>& tris, int n,
                                                       int tile_size, int margin, bool every_face);

size_t adaptive_sweep(const std::vector<FaceSweep>& sweeps, const AdaptiveSpacing& spacing,
                      const std::vector<std::vector<uint32_t>>& bases, double min_length,
                      const ChordRound& run_round, const SweepEstimate& estimate = {});

}  // namespace vislib
