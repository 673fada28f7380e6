// Bullet 3.24 (btGjkEpaSolver2, built with BT_USE_DOUBLE_PRECISION against Debian's float64 libraries) on
// convex hulls given as local vertices and poses. Shapes are btConvexHullShape with a zero margin, queried
// without margins; a shape is created once per hull (pd_bt_hull_new) and reused across queries.
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <LinearMath/btTransform.h>
#include <cstddef>

#ifndef BT_USE_DOUBLE_PRECISION
#error "the Bullet shim must be built in double precision (pkg-config bullet-float64)"
#endif

namespace {
btTransform pose(const double t[3], const double q[4]) {
    // q is (w, x, y, z); btQuaternion takes (x, y, z, w).
    return btTransform(btQuaternion(q[1], q[2], q[3], q[0]), btVector3(t[0], t[1], t[2]));
}

void write(const btVector3 &v, double out[3]) {
    out[0] = v.x();
    out[1] = v.y();
    out[2] = v.z();
}
}  // namespace

extern "C" {

void *pd_bt_hull_new(const double *verts, size_t n) {
    auto *shape = new btConvexHullShape(verts, (int)n, (int)(3 * sizeof(double)));
    shape->setMargin(0.0);
    return shape;
}

void pd_bt_hull_free(void *shape) { delete static_cast<btConvexHullShape *>(shape); }

// mode 0: Penetration (true when penetrating: distance < 0 is minus the depth); mode 1: Distance (true when
// separated). Returns 1 when the call returned true, 0 when false, and writes Bullet's status, signed
// distance, normal and witness points (world) in every case. Bullet runs GJK and EPA in the first shape's
// frame and returns the witnesses in world coordinates but the normal in that frame: it is rotated to the
// world here.
int pd_bt_query(const void *a, const double ta[3], const double qa[4], const void *b, const double tb[3],
                const double qb[4], int mode, int *status, double *distance, double normal[3],
                double wa[3], double wb[3]) {
    const auto *sa = static_cast<const btConvexHullShape *>(a);
    const auto *sb = static_cast<const btConvexHullShape *>(b);
    btTransform pa = pose(ta, qa), pb = pose(tb, qb);
    btVector3 guess = pb.getOrigin() - pa.getOrigin();
    btGjkEpaSolver2::sResults r;
    bool ok = mode == 0 ? btGjkEpaSolver2::Penetration(sa, pa, sb, pb, guess, r, false)
                        : btGjkEpaSolver2::Distance(sa, pa, sb, pb, guess, r);
    *status = (int)r.status;
    *distance = r.distance;
    write(pa.getBasis() * r.normal, normal);
    write(r.witnesses[0], wa);
    write(r.witnesses[1], wb);
    return ok ? 1 : 0;
}
}
