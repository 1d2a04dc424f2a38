/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenWallMesh: the stepped geometries (force-dependent motion, free motion); see
   fix_musen_wall_mesh.h.

   Re-implemented from MUSEN 1.74.2 (BSD-3-Clause, (c) MUSEN Development Team, e0ff360):
   CGeometryMotion::UpdateMotionInfo (Modules/Geometries/GeometryMotion.cpp),
   CCPUSimulator::MoveWalls (Modules/Simulator/CPUSimulator.cpp) and the rotation matrix of
   CQuaternion (GeneralSources/Quaternion.h), in MUSEN's order of floating-point operations.
------------------------------------------------------------------------- */

#include "fix_musen_wall_mesh.h"

#include "comm.h"
#include "update.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;

namespace {
bool zero3(const double *a)
{
  return a[0] == 0 && a[1] == 0 && a[2] == 0;
}
}    // namespace

/* CGeometryMotion::UpdateMotionInfo: the motion acting after this value (the time for
   time-dependent motion, the z force on the geometry for force-dependent motion). */
void FixMusenWallMesh::update_motion(Geometry &G, double value)
{
  auto set = [&G](const double *v, const double *c, const double *w) {
    for (int k = 0; k < 3; k++) {
      G.cur_v[k] = v[k];
      G.cur_c[k] = c[k];
      G.cur_w[k] = w[k];
    }
  };
  auto clear = [&G]() {
    for (int k = 0; k < 3; k++) G.cur_v[k] = G.cur_c[k] = G.cur_w[k] = 0.0;
  };
  const long n_int = static_cast<long>(G.intervals.size());
  const long n_force = static_cast<long>(G.fints.size());
  switch (G.motion_kind) {
    case 1: {    // time: the first interval from the current one holding the value
      bool found = false;
      for (long i = G.imotion < 0 ? 0 : G.imotion; i < n_int && !found; ++i) {
        const Interval &I = G.intervals[i];
        if (I.tb <= value && value <= I.te) {
          found = true;
          if (G.imotion != i) {
            G.imotion = i;
            set(I.v, I.c, I.w);
          }
        }
      }
      if (!found) clear();
      break;
    }
    case 2: {    // force: one interval after the other, each until its limit is passed
      if (G.imotion < 0) {
        G.imotion = 0;
        set(G.fints[0].v, G.fints[0].c, G.fints[0].w);
      }
      if (G.imotion >= n_force) {
        clear();
        break;
      }
      const ForceInterval &F = G.fints[G.imotion];
      const bool passed = F.max ? value > F.limit : value < F.limit;
      if (passed) {
        ++G.imotion;
        if (G.imotion >= n_force)
          clear();
        else
          set(G.fints[G.imotion].v, G.fints[G.imotion].c, G.fints[G.imotion].w);
      }
      break;
    }
    case 3: {    // constant force: the first interval, reversed while its limit is passed
      G.imotion = 0;
      const ForceInterval &F = G.fints[0];
      set(F.v, F.c, F.w);
      const bool passed = F.max ? value > F.limit : value < F.limit;
      if (passed)
        for (int k = 0; k < 3; k++) {
          G.cur_w[k] *= -1;
          G.cur_v[k] *= -1;
        }
      break;
    }
    default:
      break;
  }
}

/* CQuaternion(w dt).ToRotmat(): the quaternion of the Euler angles XYZ w dt
   (SetFromEulerAnglesXYZ, normalized with q0 >= 0), normalized again, as a matrix */
void FixMusenWallMesh::rotation_matrix(const double *w, double dt, double R[3][3])
{
  const double a[3] = {w[0] * dt, w[1] * dt, w[2] * dt};
  const double c1 = std::cos(a[2] * 0.5), s1 = std::sin(a[2] * 0.5);
  const double c2 = std::cos(a[1] * 0.5), s2 = std::sin(a[1] * 0.5);
  const double c3 = std::cos(a[0] * 0.5), s3 = std::sin(a[0] * 0.5);
  double q[4] = {c1 * c2 * c3 + s1 * s2 * s3, c1 * c2 * s3 - s1 * s2 * c3,
                 c1 * s2 * c3 + s1 * c2 * s3, s1 * c2 * c3 - c1 * s2 * s3};
  for (int pass = 0; pass < 2; pass++) {    // Normalize, in the constructor and in ToRotmat
    double sum = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (q[0] < 0) sum *= -1;
    for (double &v : q) v /= sum;
  }
  const double w1 = q[0] * q[0], w2 = q[1] * q[1], w3 = q[2] * q[2], w4 = q[3] * q[3];
  const double ij = 2 * q[1] * q[2], ik = 2 * q[1] * q[3], jk = 2 * q[2] * q[3];
  const double iw = 2 * q[1] * q[0], jw = 2 * q[2] * q[0], kw = 2 * q[3] * q[0];
  const double M[3][3] = {{w1 + w2 - w3 - w4, ij - kw, jw + ik},
                          {ij + kw, w1 - w2 + w3 - w4, jk - iw},
                          {ik - jw, jk + iw, w1 - w2 - w3 + w4}};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) R[i][j] = M[i][j];
}

/* the area-weighted centroid of the geometry's triangles now (MoveWalls, RotateAroundCenter) */
void FixMusenWallMesh::centroid(const Geometry &G, double *centre) const
{
  double total_area = 0.0, weighted[3] = {0, 0, 0};
  for (int tr : G.tris) {
    const double *p = &vert[9 * (size_t) tr];
    double u[3], w[3];
    for (int k = 0; k < 3; k++) {
      u[k] = p[3 + k] - p[k];
      w[k] = p[6 + k] - p[k];
    }
    const double c[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double area = 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    total_area += area;
    for (int k = 0; k < 3; k++) weighted[k] += area * ((p[k] + p[3 + k] + p[6 + k]) / 3.);
  }
  for (int k = 0; k < 3; k++) centre[k] = total_area != 0.0 ? weighted[k] / total_area : 0.0;
}

/* CCPUSimulator::MoveWalls for the stepped geometries, from the triangle forces in ftri
   (the last force evaluation's) at MUSEN's time t of that evaluation, by the step dt. */
void FixMusenWallMesh::step_walls(double t, double dt)
{
  MPI_Allreduce(ftri.data(), ftri_all.data(), 3 * ntri, MPI_DOUBLE, MPI_SUM, world);
  reduced_valid = false;
  for (auto &G : geoms) {
    if (!G.stepped || G.tris.empty()) continue;
    if (G.motion_kind == 2 || G.motion_kind == 3) {
      double fz = 0;
      for (int tr : G.tris) fz += ftri_all[3 * (size_t) tr + 2];
      update_motion(G, fz);
    } else {
      update_motion(G, t);
    }
    double vel[3] = {G.cur_v[0], G.cur_v[1], G.cur_v[2]};
    const bool is_free = G.free_axis[0] || G.free_axis[1] || G.free_axis[2];
    if (is_free && G.mass != 0.0) {
      // Newton's law for the geometry: gravity x mass plus the walls' forces, from the mean
      // velocity its walls had
      double total[3], mean[3] = {0, 0, 0};
      for (int k = 0; k < 3; k++) total[k] = gravity[k] * G.mass;
      const double n = static_cast<double>(G.tris.size());
      for (int tr : G.tris)
        for (int k = 0; k < 3; k++) {
          total[k] += ftri_all[3 * (size_t) tr + k];
          mean[k] += G.vel[k] / n;
        }
      for (int k = 0; k < 3; k++)
        if (G.free_axis[k]) vel[k] = mean[k] + dt * total[k] / G.mass;
    }
    double centre[3] = {G.cur_c[0], G.cur_c[1], G.cur_c[2]};
    if (G.around_centre) centroid(G, centre);
    // no motion: MUSEN leaves the walls and the velocity they carry as they are
    if (zero3(vel) && zero3(G.cur_w)) continue;
    for (int k = 0; k < 3; k++) {
      G.vel[k] = vel[k];
      G.rotvel[k] = G.cur_w[k];
      G.rotcentre[k] = centre[k];
    }
    double R[3][3];
    const bool rotates = !zero3(G.cur_w);
    if (rotates) rotation_matrix(G.cur_w, dt, R);
    for (int tr : G.tris) {
      double *p = &vert[9 * (size_t) tr];
      // rotate about the centre first, then translate (MoveWalls)
      if (rotates)
        for (int a = 0; a < 3; a++) {
          const double r[3] = {p[3 * a] - centre[0], p[3 * a + 1] - centre[1], p[3 * a + 2] - centre[2]};
          for (int k = 0; k < 3; k++) p[3 * a + k] = centre[k] + (R[k][0] * r[0] + R[k][1] * r[1] + R[k][2] * r[2]);
        }
      if (!zero3(vel))
        for (int a = 0; a < 3; a++)
          for (int k = 0; k < 3; k++) p[3 * a + k] += vel[k] * dt;
      if (rotates) {    // Normalized((v2 - v1) x (v3 - v1))
        double u[3], w[3], c[3];
        for (int k = 0; k < 3; k++) {
          u[k] = p[3 + k] - p[k];
          w[k] = p[6 + k] - p[k];
        }
        c[0] = u[1] * w[2] - u[2] * w[1];
        c[1] = u[2] * w[0] - u[0] * w[2];
        c[2] = u[0] * w[1] - u[1] * w[0];
        const double len = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        for (int k = 0; k < 3; k++) nrm[3 * (size_t) tr + k] = len != 0 ? c[k] / len : 0.0;
      }
      for (int k = 0; k < 3; k++) {
        tlo[3 * (size_t) tr + k] = std::min(std::min(p[k], p[3 + k]), p[6 + k]);
        thi[3 * (size_t) tr + k] = std::max(std::max(p[k], p[3 + k]), p[6 + k]);
      }
    }
  }
}

/* restart: started, pending, then per geometry imotion, current motion (9), wall motion (9),
   then every triangle's vertices */
std::vector<double> FixMusenWallMesh::stepped_state() const
{
  std::vector<double> out;
  if (!any_stepped) return out;
  out.push_back(started ? 1.0 : 0.0);
  out.push_back(pending ? 1.0 : 0.0);
  for (const auto &G : geoms) {
    out.push_back(static_cast<double>(G.imotion));
    for (const double *a : {G.cur_v, G.cur_c, G.cur_w, G.vel, G.rotvel, G.rotcentre})
      out.insert(out.end(), a, a + 3);
  }
  out.insert(out.end(), vert.begin(), vert.end());
  return out;
}

void FixMusenWallMesh::restore_stepped(const double *list)
{
  started = list[0] != 0.0;
  pending = list[1] != 0.0;
  size_t k = 2;
  for (auto &G : geoms) {
    G.imotion = static_cast<long>(list[k++]);
    for (double *a : {G.cur_v, G.cur_c, G.cur_w, G.vel, G.rotvel, G.rotcentre}) {
      std::copy(list + k, list + k + 3, a);
      k += 3;
    }
  }
  std::copy(list + k, list + k + vert.size(), vert.begin());
  for (int tr = 0; tr < ntri; tr++) {
    const double *p = &vert[9 * (size_t) tr];
    for (int c = 0; c < 3; c++) {
      tlo[3 * (size_t) tr + c] = std::min(std::min(p[c], p[3 + c]), p[6 + c]);
      thi[3 * (size_t) tr + c] = std::max(std::max(p[c], p[3 + c]), p[6 + c]);
    }
  }
}
