#include "Quality/LocalChangeVeto.h"

#include "Spatial/Geometry.h"
#include "Spatial/TriangleTree.h"

#include <algorithm>

namespace sdfcage
{

namespace
{

inline bool separatedImpl(const Vec3 a[3], const Vec3 b[3], const Vec3& u, double gap)
{
  const double n = u.norm();
  if (!(n > 0))
    return false;
  const double a0 = u.dot(a[0]), a1 = u.dot(a[1]), a2 = u.dot(a[2]);
  const double b0 = u.dot(b[0]), b1 = u.dot(b[1]), b2 = u.dot(b[2]);
  const double g = gap * n * (1 + 1e-9);
  return std::min({ b0, b1, b2 }) - std::max({ a0, a1, a2 }) >= g ||
    std::min({ a0, a1, a2 }) - std::max({ b0, b1, b2 }) >= g;
}

inline bool oneSideImpl(const Vec3& a, const Vec3& n, const Vec3& d, const Vec3& e)
{
  const Vec3 ad = d - a, ae = e - a;
  const double sd = n.dot(ad), se = n.dot(ae);
  const double nn = n.norm();
  const double td = 1e-6 * nn * ad.norm(), te = 1e-6 * nn * ae.norm();
  return (sd > td && se > te) || (sd < -td && se < -te);
}

inline bool separatedByAxesImpl(const ChangedTriangle& a, const LocalChangeScratch::Candidate& b, double gap)
{
  if (separatedImpl(a.Pts, b.Pts, b.C - a.C, gap) || separatedImpl(a.Pts, b.Pts, a.N, gap))
    return true;
  const Vec3 nb = (b.Pts[1] - b.Pts[0]).cross(b.Pts[2] - b.Pts[0]);
  if (separatedImpl(a.Pts, b.Pts, nb, gap))
    return true;
  for (int k = 0; k < 3; ++k)
    if (separatedImpl(a.Pts, b.Pts, a.N.cross(a.Pts[(k + 1) % 3] - a.Pts[k]), gap) ||
      separatedImpl(a.Pts, b.Pts, nb.cross(b.Pts[(k + 1) % 3] - b.Pts[k]), gap))
      return true;
  return false;
}

} // namespace

const char* verdictName(LocalChangeVerdict v)
{
  switch (v)
  {
    case LocalChangeVerdict::Accepted:
      return "accepted";
    case LocalChangeVerdict::Shape:
      return "shape";
    case LocalChangeVerdict::Fold:
      return "fold";
    case LocalChangeVerdict::InputClearance:
      return "input clearance";
    case LocalChangeVerdict::SelfIntersection:
      return "self-intersection";
  }
  return "?";
}

LocalChangeVerdict LocalChangeVeto::check(LocalChangeScratch& s, LocalChangeFindings* findings) const
{
  if (findings)
    findings->Read = false;
  if (!shapeOk(s.Tris))
    return LocalChangeVerdict::Shape;
  if (Policy.CheckSelfIntersection && !foldFree(s.Tris))
    return LocalChangeVerdict::Fold;
  if (Policy.Input != LocalChangePolicy::InputTest::None && !inputClear(s.Tris))
    return LocalChangeVerdict::InputClearance;
  if (Policy.CheckSelfIntersection && !selfIntersectionFree(s, findings))
    return LocalChangeVerdict::SelfIntersection;
  return LocalChangeVerdict::Accepted;
}

bool LocalChangeVeto::shapeOk(std::vector<ChangedTriangle>& tris) const
{
  for (ChangedTriangle& t : tris)
  {
    const double floor = Policy.KeepQualityBefore ? std::min(Policy.MinimumTriangleQuality, t.QualityBefore)
                                                  : Policy.MinimumTriangleQuality;
    if (triangleQuality(t.Pts[0], t.Pts[1], t.Pts[2]) < floor)
      return false;
    t.N = (t.Pts[1] - t.Pts[0]).cross(t.Pts[2] - t.Pts[0]);
    t.C = (t.Pts[0] + t.Pts[1] + t.Pts[2]) / 3.0;
    t.R = std::max({ (t.Pts[0] - t.C).norm(), (t.Pts[1] - t.C).norm(), (t.Pts[2] - t.C).norm() });
    // (written so that a NaN normal is a flip)
    if (!(t.Reference.dot(t.N) > Policy.MinimumNormalCosine * t.Reference.norm() * t.N.norm()))
      return false;
  }
  return true;
}

bool LocalChangeVeto::foldFree(const std::vector<ChangedTriangle>& tris) const
{
  for (std::size_t i = 0; i < tris.size(); ++i)
    for (std::size_t j = i + 1; j < tris.size(); ++j)
      if (trianglesConflict(
            tris[i].Ids, tris[i].Pts, tris[j].Ids, tris[j].Pts, Policy.SelfClearance, Policy.FoldCosine))
        return false;
  return true;
}

bool LocalChangeVeto::inputClear(const std::vector<ChangedTriangle>& tris) const
{
  // The triangles go to the tree together (anyCloserThanAny: one walk for all, the same
  // verdict). Measured, median of 5 (session 48): the simplification of octopus-low 0.214 ->
  // 0.199 s, armadillo 0.461 -> 0.425 s, anchor 0.159 -> 0.145 s.
  const Vec3* exact[32];
  int exacts = 0;
  auto exactlyClear = [&]() { return !Input.anyCloserThanAny(exact, exacts, Policy.Clearance); };
  for (const ChangedTriangle& t : tris)
  {
    exact[exacts++] = t.Pts;
    if (exacts == 32 && !exactlyClear())
      return false;
    exacts %= 32;
  }
  return exactlyClear();
}

bool LocalChangeVeto::selfIntersectionFree(LocalChangeScratch& s, LocalChangeFindings* findings) const
{
  const double selfDelta = Policy.SelfClearance;
  const bool parts = Policy.PartClearance > selfDelta && Cage.Part && !Cage.Part->empty();
  const double reach = parts ? Policy.PartClearance : selfDelta;
  const std::vector<Vec3>& P = *Cage.Points;
  const std::vector<Triangle>& T = *Cage.Triangles;
  // one grid query for the whole new one-ring, then per pair a box test, the early-outs and the
  // exact conflict test
  Vec3 ringLo = Vec3::Constant(std::numeric_limits<double>::infinity()), ringHi = -ringLo;
  for (const ChangedTriangle& t : s.Tris)
    for (const Vec3& q : t.Pts)
    {
      ringLo = ringLo.cwiseMin(q);
      ringHi = ringHi.cwiseMax(q);
    }
  ringLo -= Vec3::Constant(reach);
  ringHi += Vec3::Constant(reach);
  if (findings)
  {
    findings->Read = true;
    findings->ReadLo = ringLo;
    findings->ReadHi = ringHi;
  }
  auto& candidates = s.Candidates;
  candidates.clear();
  s.Seen.begin(T.size());
  Cage.Grid->query(ringLo, ringHi, [&](int f) {
    if ((Cage.Alive && !(*Cage.Alive)[f]) || s.Replaced.contains(f) || !s.Seen.insert(f))
      return;
    LocalChangeScratch::Candidate c;
    c.F = f;
    for (int k = 0; k < 3; ++k)
    {
      c.Ids[k] = T[f][k];
      c.Pts[k] = P[T[f][k]];
    }
    if (Cage.BoxLo)
    {
      c.Lo = (*Cage.BoxLo)[f];
      c.Hi = (*Cage.BoxHi)[f];
    }
    else
    {
      c.Lo = c.Pts[0].cwiseMin(c.Pts[1]).cwiseMin(c.Pts[2]);
      c.Hi = c.Pts[0].cwiseMax(c.Pts[1]).cwiseMax(c.Pts[2]);
    }
    if ((c.Lo.array() > ringHi.array()).any() || (c.Hi.array() < ringLo.array()).any())
      return;
    c.R = -1; // the bounding sphere when first needed
    candidates.push_back(c);
  });
  for (const ChangedTriangle& nt : s.Tris)
  {
    const Vec3 lo = nt.Pts[0].cwiseMin(nt.Pts[1]).cwiseMin(nt.Pts[2]) - Vec3::Constant(reach);
    const Vec3 hi = nt.Pts[0].cwiseMax(nt.Pts[1]).cwiseMax(nt.Pts[2]) + Vec3::Constant(reach);
    const int ntPart = parts ? (*Cage.Part)[nt.Ids[0]] : 0;
    for (auto& c : candidates)
    {
      if ((c.Lo.array() > hi.array()).any() || (c.Hi.array() < lo.array()).any())
        continue;
      // another part keeps PartClearance (it shares no vertex with this one)
      const double delta = parts && (*Cage.Part)[c.Ids[0]] != ntPart ? Policy.PartClearance : selfDelta;
      int shared = 0, ka = -1, kb = -1;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (nt.Ids[i] == c.Ids[j])
          {
            ++shared;
            ka = i;
            kb = j;
          }
      const bool disjoint = shared == 0;
      // sharing one vertex: they cannot meet elsewhere when the other two corners of one lie
      // strictly on one side of the other's plane (by an angle far above rounding, so
      // meetBeyondSharedVertex's nearly-coplanar case cannot apply)
      if (shared == 1 &&
        (oneSideImpl(nt.Pts[ka], nt.N, c.Pts[(kb + 1) % 3], c.Pts[(kb + 2) % 3]) ||
          oneSideImpl(
            c.Pts[kb], (c.Pts[1] - c.Pts[0]).cross(c.Pts[2] - c.Pts[0]), nt.Pts[(ka + 1) % 3], nt.Pts[(ka + 2) % 3])))
        continue;
      if (disjoint && c.R < 0)
      {
        c.C = (c.Pts[0] + c.Pts[1] + c.Pts[2]) / 3.0;
        c.R = std::max({ (c.Pts[0] - c.C).norm(), (c.Pts[1] - c.C).norm(), (c.Pts[2] - c.C).norm() });
      }
      // disjoint triangles whose bounding spheres are farther apart than delta cannot conflict
      if (disjoint && (c.C - nt.C).norm() - c.R - nt.R >= delta)
        continue;
      // nor those a separating axis keeps delta apart
      if (disjoint && separatedByAxesImpl(nt, c, delta))
        continue;
      if (!trianglesConflict(nt.Ids, nt.Pts, c.Ids, c.Pts, delta, Policy.FoldCosine))
        continue;
      if (!Policy.RelaxCloserPairs || !disjoint)
        return false;
      // a pair already closer than the self clearance keeps half its distance, and never touches
      const double d0 = std::sqrt(triangleTriangleDistance2(nt.Before, c.Pts));
      const double d2 = triangleTriangleDistance2(nt.Pts, c.Pts);
      if (d0 >= selfDelta || d2 == 0.0 || d2 < Policy.relaxed(d0) * Policy.relaxed(d0))
        return false;
    }
  }
  return true;
}

bool LocalChangeVeto::separated(const Vec3 a[3], const Vec3 b[3], const Vec3& u, double gap)
{
  return separatedImpl(a, b, u, gap);
}

bool LocalChangeVeto::oneSide(const Vec3& a, const Vec3& n, const Vec3& d, const Vec3& e)
{
  return oneSideImpl(a, n, d, e);
}

bool LocalChangeVeto::separatedByAxes(const ChangedTriangle& a, const LocalChangeScratch::Candidate& b, double gap)
{
  return separatedByAxesImpl(a, b, gap);
}

} // namespace sdfcage
