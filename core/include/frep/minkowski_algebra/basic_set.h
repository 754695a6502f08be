// Roerdink-Minkowski's basic set (§IV.A) and the canonical form of a multiple Minkowski sum of
// its members (Theorem 1): segments and discs along x/y/z, spheres and blocks, each placed at a
// point and, for the rotated variants (eq. 17), turned by a rotation R. A sum of any number of
// members that share one frame R (spheres fit every frame) is
//
//   offset + R · ( block[0, L] ⊕ xdisc(rx) ⊕ ydisc(ry) ⊕ zdisc(rz) ⊕ ball(rs) )
//
// because members of one type add their parameters (the paper's basic assumption: lengths,
// radii and placements add). That is the secondary object of the sum.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace frep::minkowski {

using Vec3 = std::array<double, 3>;
// Row-major 3×3 rotation; its columns are the frame's axes in world coordinates.
using Mat3 = std::array<double, 9>;

Mat3 identityRotation();
// Right-handed rotations about x, then y, then z (radians): R = Rz · Ry · Rx, as hfRotate3D*
// applied in that order moves a solid.
Mat3 rotationXYZ(double ax, double ay, double az);
bool sameRotation(const Mat3& a, const Mat3& b);

enum class ShapeKind { Segment, Disc, Sphere, Block };

// One member of the basic set. Segment: from pos to pos + R·(size[0]·e_axis) (size[0] may be
// negative). Disc: radius size[0] >= 0 around pos in the plane through pos with normal R·e_axis.
// Sphere: radius size[0] >= 0 around pos. Block: corner pos, edges R·(size[i]·e_i).
struct Shape {
  ShapeKind kind = ShapeKind::Sphere;
  int axis = 0;  // 0, 1, 2 for x, y, z (segments and discs)
  Vec3 size{0, 0, 0};
  Vec3 pos{0, 0, 0};
  Mat3 rot = identityRotation();
  std::string describe() const;  // "zdisc(r 0.5 at (0, 0, 1))"
};

// The secondary object of a sum (see the file comment).
struct Sum {
  Mat3 rot = identityRotation();
  bool hasFrame = false;  // a non-sphere member fixed rot
  Vec3 offset{0, 0, 0};   // world position of the local origin
  Vec3 lengths{0, 0, 0};  // the block's edges (sum of the segments and blocks), >= 0
  Vec3 disc{0, 0, 0};     // disc radius per axis (sum of the discs along that axis), >= 0
  double ball = 0;        // sphere radius (sum of the spheres), >= 0
  int terms = 0;          // members added

  // Adds a member; false (sum unchanged) when its frame differs from the sum's (then the sum
  // is not in one frame and eq. 17 does not apply).
  bool add(const Shape& s);
  // Adds another sum (associativity, eq. 4); false when their frames differ.
  bool add(const Sum& s);
  int discAxes() const;  // number of axes with a disc radius > 0
  std::string describe() const;
};

Sum sumOf(const Shape& s);

}  // namespace frep::minkowski
