// coal 3.0 (the hpp-fcl successor, from its `libcoal` wheel) on convex hulls given as local vertices,
// triangulated faces and poses, in double precision.
//
// A hull is a coal::Convex<coal::Triangle> built once (pd_coal_hull_new) from the hull's vertices and its
// faces split into fans; coal builds the vertex adjacency from them (hill-climbing supports above 32
// vertices). A query is GJKSolver::shapeDistance with penetration on: the narrow phase coal's own
// `distance` and `collide` run for a pair of convex shapes. One solver per thread is reused across queries,
// as a user keeps one; only its tolerances are set per call. coal's exceptions are caught and reported as a
// failed call.
#include <coal/narrowphase/narrowphase.h>
#include <coal/shape/convex.h>

#include <cstddef>
#include <exception>
#include <memory>
#include <vector>

namespace {
coal::Transform3s pose(const double t[3], const double q[4]) {
  // q is (w, x, y, z), Eigen's constructor order.
  return coal::Transform3s(coal::Quatf(q[0], q[1], q[2], q[3]),
                           coal::Vec3s(t[0], t[1], t[2]));
}

void write(const coal::Vec3s &v, double out[3]) {
  out[0] = v[0];
  out[1] = v[1];
  out[2] = v[2];
}

coal::GJKSolver &solver() {
  thread_local coal::GJKSolver s;
  return s;
}
}  // namespace

extern "C" {

// `verts`: n × 3 local coordinates; `tris`: m × 3 vertex indices, counter-clockwise seen from outside.
// Returns null when coal rejects the hull.
void *pd_coal_hull_new(const double *verts, size_t n, const unsigned *tris, size_t m) {
  try {
    auto points = std::make_shared<std::vector<coal::Vec3s>>();
    points->reserve(n);
    for (size_t i = 0; i < n; i++) {
      points->emplace_back(verts[3 * i], verts[3 * i + 1], verts[3 * i + 2]);
    }
    auto polygons = std::make_shared<std::vector<coal::Triangle>>();
    polygons->reserve(m);
    for (size_t i = 0; i < m; i++) {
      polygons->emplace_back(tris[3 * i], tris[3 * i + 1], tris[3 * i + 2]);
    }
    auto *shape = new coal::Convex<coal::Triangle>(points, (unsigned)n, polygons, (unsigned)m);
    shape->computeLocalAABB();
    return shape;
  } catch (const std::exception &) {
    return nullptr;
  }
}

void pd_coal_hull_free(void *shape) { delete static_cast<coal::Convex<coal::Triangle> *>(shape); }

// One query. `tolerance` <= 0 keeps coal's defaults (GJK and EPA tolerances 1e-6, absolute), otherwise it
// is used for both. Writes the signed distance (< 0: minus the penetration depth), the normal (world, from
// the first shape to the second), the witness points (world) and the GJK and EPA statuses. Returns 0, or
// -1 when coal threw.
int pd_coal_query(const void *a, const double ta[3], const double qa[4], const void *b,
                  const double tb[3], const double qb[4], double tolerance, double *distance,
                  double normal[3], double p1[3], double p2[3], int *gjk_status, int *epa_status) {
  const auto &sa = *static_cast<const coal::Convex<coal::Triangle> *>(a);
  const auto &sb = *static_cast<const coal::Convex<coal::Triangle> *>(b);
  coal::GJKSolver &s = solver();
  s.gjk_tolerance = tolerance > 0.0 ? tolerance : coal::GJK_DEFAULT_TOLERANCE;
  s.epa_tolerance = tolerance > 0.0 ? tolerance : coal::EPA_DEFAULT_TOLERANCE;
  try {
    coal::Vec3s w1, w2, n;
    *distance = s.shapeDistance(sa, pose(ta, qa), sb, pose(tb, qb), true, w1, w2, n);
    write(n, normal);
    write(w1, p1);
    write(w2, p2);
    *gjk_status = (int)s.gjk.status;
    *epa_status = (int)s.epa.status;
    return 0;
  } catch (const std::exception &) {
    return -1;
  }
}
}
