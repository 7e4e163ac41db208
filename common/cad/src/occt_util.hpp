#pragma once
// Conversions between OCCT and Eigen. Internal to rigger_cad.

#include <Eigen/Core>
#include <gp_Dir.hxx>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

namespace rigger::cad {

inline Eigen::Vector3d to_eigen(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }
inline Eigen::Vector3d to_eigen(const gp_Vec& v) { return {v.X(), v.Y(), v.Z()}; }
inline Eigen::Vector3d to_eigen(const gp_Dir& d) { return {d.X(), d.Y(), d.Z()}; }
inline gp_Pnt to_gp_pnt(const Eigen::Vector3d& p) { return gp_Pnt(p.x(), p.y(), p.z()); }

}  // namespace rigger::cad
