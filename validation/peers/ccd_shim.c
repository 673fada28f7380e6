/* libccd 2.1 (double precision) on two convex hulls given as local vertices and poses.
 *
 * Each hull is its vertex list in its own frame plus a pose (translation, unit quaternion w, x, y, z);
 * the support map is a linear scan in the local frame. libccd's EPA has no iteration cap and can loop with
 * tight tolerances: the support map counts its calls and, past `support_cap`, jumps back to the entry
 * point, which reports the query as failed (PD_CCD_CAP). The polytope libccd allocated is then leaked; a
 * harness run meets this a bounded number of times. */
#include <ccd/ccd.h>
#include <setjmp.h>
#include <stddef.h>

typedef struct {
    const double *verts; /* n × 3, local frame */
    size_t n;
    double t[3];
    double q[4]; /* w, x, y, z */
    unsigned long *calls;
    unsigned long cap;
    jmp_buf *escape;
} pd_hull;

enum { PD_CCD_SEPARATED = 0, PD_CCD_OVERLAP = 1, PD_CCD_ERROR = -1, PD_CCD_CAP = -2 };

/* v' = q v q*, for unit q = (w, u). */
static void rotate(const double q[4], const double v[3], double out[3]) {
    double w = q[0], x = q[1], y = q[2], z = q[3];
    double tx = 2.0 * (y * v[2] - z * v[1]);
    double ty = 2.0 * (z * v[0] - x * v[2]);
    double tz = 2.0 * (x * v[1] - y * v[0]);
    out[0] = v[0] + w * tx + (y * tz - z * ty);
    out[1] = v[1] + w * ty + (z * tx - x * tz);
    out[2] = v[2] + w * tz + (x * ty - y * tx);
}

static void support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *vec) {
    const pd_hull *h = (const pd_hull *)obj;
    if (++*h->calls > h->cap) {
        longjmp(*h->escape, 1);
    }
    double qi[4] = {h->q[0], -h->q[1], -h->q[2], -h->q[3]};
    double d[3] = {ccdVec3X(dir), ccdVec3Y(dir), ccdVec3Z(dir)};
    double dl[3];
    rotate(qi, d, dl);
    size_t best = 0;
    double best_dot = -1e308;
    for (size_t i = 0; i < h->n; i++) {
        const double *p = h->verts + 3 * i;
        double s = p[0] * dl[0] + p[1] * dl[1] + p[2] * dl[2];
        if (s > best_dot) {
            best_dot = s;
            best = i;
        }
    }
    double w[3];
    rotate(h->q, h->verts + 3 * best, w);
    ccdVec3Set(vec, w[0] + h->t[0], w[1] + h->t[1], w[2] + h->t[2]);
}

static void center(const void *obj, ccd_vec3_t *c) {
    const pd_hull *h = (const pd_hull *)obj;
    ccdVec3Set(c, h->t[0], h->t[1], h->t[2]);
}

/* One query. `method` 0: GJK+EPA (ccdGJKPenetration), 1: MPR (ccdMPRPenetration). `tolerance` <= 0 keeps
 * libccd's defaults (CCD_INIT), otherwise it is used as epa, mpr and distance tolerance (m). On
 * PD_CCD_OVERLAP, `depth` and `dir` (world, the direction obj2 moves to separate) are written. */
int pd_ccd_penetration(const double *va, size_t na, const double ta[3], const double qa[4],
                       const double *vb, size_t nb, const double tb[3], const double qb[4], int method,
                       double tolerance, unsigned long support_cap, double *depth, double dir[3]) {
    jmp_buf escape;
    unsigned long calls = 0;
    pd_hull a = {va, na, {ta[0], ta[1], ta[2]}, {qa[0], qa[1], qa[2], qa[3]}, &calls, support_cap, &escape};
    pd_hull b = {vb, nb, {tb[0], tb[1], tb[2]}, {qb[0], qb[1], qb[2], qb[3]}, &calls, support_cap, &escape};
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = support;
    ccd.support2 = support;
    ccd.center1 = center;
    ccd.center2 = center;
    if (tolerance > 0.0) {
        ccd.epa_tolerance = tolerance;
        ccd.mpr_tolerance = tolerance;
        ccd.dist_tolerance = tolerance;
    }
    if (setjmp(escape) != 0) {
        return PD_CCD_CAP;
    }
    ccd_real_t d = 0.0;
    ccd_vec3_t n, pos;
    int r = method == 0 ? ccdGJKPenetration(&a, &b, &ccd, &d, &n, &pos)
                        : ccdMPRPenetration(&a, &b, &ccd, &d, &n, &pos);
    if (r == 0) {
        *depth = d;
        dir[0] = ccdVec3X(&n);
        dir[1] = ccdVec3Y(&n);
        dir[2] = ccdVec3Z(&n);
        return PD_CCD_OVERLAP;
    }
    return r == -1 ? PD_CCD_SEPARATED : PD_CCD_ERROR;
}
