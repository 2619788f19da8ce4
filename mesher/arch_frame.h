// An arch-following frame for mandibles, in which the grid mesher lays its grid along the dental arch.
//
// Input: a closed surface of a whole mandible in the mandible frame (+x subject's left, +y posterior,
// +z superior, mm), as `hexbite generate mandible` writes it and as the real jaw in ../shared/data/jaw is.
// Output: the map between the body (x, y, z) and arch coordinates (s, t, z): s the arc length along the
// arch's medial curve in the horizontal plane (from the right end), t the signed distance from that curve
// across the bone (positive inward, lingual), z unchanged. The bone's body and rami become a straight bar,
// so that an overlay grid meets their walls square instead of cutting the curved arch obliquely.
// Algorithm: the medial curve is a polar curve rho(theta) about a point behind the bone (midway between the
// sides, 0.3 of the bone's depth behind its back; 1.0 when that map fails its checks, as for a narrow or a
// deep arch): the triangles' area-weighted mean radius in 80 angle
// bins, fitted by a least-squares polynomial of degree 6 (Eigen); straight beyond the bone's angles. A point
// maps to the curve's closest point (Newton steps on the angle from its own polar angle), s by a table of
// the arc length. Hand-written: no library offers such a straightening map.
// Cost: O(n) to fit for n triangles (and to check the map on every vertex); O(1) per mapped point: to_arch
// scans every 8th tabulated point and takes a few Newton steps, to_body binary-searches the table.
// Thread-safe after construction (const).
#pragma once

#include <string>
#include <vector>

#include "common/error.h"
#include "mesher/tri_surface.h"

namespace hexbite {

// The surface follows no arch in the mandible frame: an InputError of the frame itself, so that a caller can
// tell it from the grid mesher's other input errors (a scenario blames its grid_frame line for this one
// only).
// Its message is the reason followed by the way out, which depends on who asked for the frame (the grid
// frame: the axis-aligned grid; the swept core: the grid core).
class NotAnArchError : public InputError {
 public:
  NotAnArchError(const std::string& reason, const std::string& way_out)
      : InputError(reason + "; " + way_out), reason_(reason) {}
  // Why the surface follows no arch, without the way out.
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

class ArchFrame {
 public:
  // Fits the frame to the surface. Throws NotAnArchError when the surface does not follow an arch in the
  // mandible frame (points that map to no unique place along the curve, or a map that folds the bone).
  explicit ArchFrame(const TriSurface& surface);

  Vec3 to_arch(const Vec3& body) const;        // (x, y, z) -> (s, t, z)
  Vec3 to_body(const Vec3& arch) const;        // (s, t, z) -> (x, y, z)
  double length() const { return s_.back(); }  // arc length of the tabulated curve, mm

 private:
  // Fits the curve about a polar centre `back` times the bone's depth behind its back, checking that the
  // curve runs inside the bone seen from above when `curve_inside`; throws NotAnArchError.
  void fit(const TriSurface& surface, double back, bool curve_inside);

  struct Point2 {
    double x, y;
  };
  double rho(double theta) const;
  Point2 curve(double theta) const;
  Point2 tangent(double theta) const;  // unit
  double theta_of_s(double s) const;
  double s_of_theta(double theta) const;

  double ox_ = 0, oy_ = 0;                 // the polar centre
  double theta_lo_ = 0, theta_hi_ = 0;     // the tabulated angles; straight beyond
  double centre_ = 0, half_width_ = 1;     // theta normalized as (theta - centre) / half_width for the fit
  std::vector<double> coefficients_;       // rho as a polynomial in the normalized angle
  std::vector<double> theta_, s_, x_, y_;  // table: angle, arc length, curve point
};

}  // namespace hexbite
