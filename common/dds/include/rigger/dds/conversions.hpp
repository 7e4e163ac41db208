#pragma once
/// @file
/// The one place where wire types (idlc structs) and domain types (Eigen, std::chrono, std::string)
/// meet. Every conversion has a round-trip test (common/dds/test/conversions_test.cpp).
///
/// Strings and sequences written into a wire struct borrow the caller's storage: the struct is valid
/// while the std::string / std::vector it points into lives and is not modified (write it, then drop it).

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <rigger/idl/types.hpp>

#include "rigger/base/time.hpp"

namespace rigger::dds {

using Vector6d = Eigen::Matrix<double, 6, 1>;  ///< (linear x y z, angular x y z)

// --- time
rigger_geometry_Time to_wire(WallTime t);
WallTime to_domain(const rigger_geometry_Time& t);
/// The current wall-clock time on the wire.
rigger_geometry_Time wire_now();

// --- geometry
rigger_geometry_Vector3 to_wire_vector(const Eigen::Vector3d& v);
rigger_geometry_Point to_wire_point(const Eigen::Vector3d& p);
rigger_geometry_Quaternion to_wire(const Eigen::Quaterniond& q);
rigger_geometry_Pose to_wire(const Eigen::Isometry3d& pose);
/// (linear; angular) as a Twist (m/s, rad/s).
rigger_geometry_Twist to_wire_twist(const Vector6d& twist);
/// (force; torque) as a Wrench (N, N m).
rigger_geometry_Wrench to_wire_wrench(const Vector6d& wrench);

Eigen::Vector3d to_domain(const rigger_geometry_Vector3& v);
Eigen::Vector3d to_domain(const rigger_geometry_Point& p);
Eigen::Quaterniond to_domain(const rigger_geometry_Quaternion& q);
/// The orientation is normalised; a zero quaternion becomes identity (callers validate separately).
Eigen::Isometry3d to_domain(const rigger_geometry_Pose& pose);
Vector6d to_domain(const rigger_geometry_Twist& twist);
Vector6d to_domain(const rigger_geometry_Wrench& wrench);
/// Row-major 6x6 covariance.
Eigen::Matrix<double, 6, 6> covariance_to_domain(const double (&cov)[36]);
void covariance_to_wire(const Eigen::Matrix<double, 6, 6>& cov, double (&out)[36]);

// --- strings and sequences
/// A std::string from a possibly-null wire string.
inline std::string to_string(const char* s) { return s ? std::string(s) : std::string(); }
/// Borrows `s` for a wire struct's string field (Cyclone does not write through it): `s` must outlive
/// the write.
inline char* wire_string(const std::string& s) { return const_cast<char*>(s.c_str()); }
/// A temporary would be destroyed before the sample is written: refused at compile time. Name the
/// string, or pass a literal.
char* wire_string(const std::string&& s) = delete;
/// A string literal lives as long as the program: safe to borrow.
template <std::size_t N>
char* wire_string(const char (&literal)[N]) {
  return const_cast<char*>(literal);
}

/// Borrows `values` for a wire sequence field (`dds_sequence_*`), which must not release it.
template <typename Seq, typename V>
void wire_sequence(Seq& seq, std::vector<V>& values) {
  seq._buffer = values.data();
  seq._length = static_cast<uint32_t>(values.size());
  seq._maximum = static_cast<uint32_t>(values.size());
  seq._release = false;
}
/// Copies a wire sequence into a vector.
template <typename V, typename Seq>
std::vector<V> to_vector(const Seq& seq) {
  std::vector<V> out;
  out.reserve(seq._length);
  for (uint32_t i = 0; i < seq._length; ++i) out.push_back(V(seq._buffer[i]));
  return out;
}
/// Borrows strings for a `sequence<string>` field: `storage` keeps the char pointers alive.
template <typename Seq>
void wire_string_sequence(Seq& seq, const std::vector<std::string>& strings, std::vector<char*>& storage) {
  storage.clear();
  for (const auto& s : strings) storage.push_back(wire_string(s));
  wire_sequence(seq, storage);
}
/// A temporary vector would be destroyed before the sample is written: refused at compile time.
template <typename Seq>
void wire_string_sequence(Seq& seq, const std::vector<std::string>&& strings, std::vector<char*>& storage) = delete;
template <typename Seq>
std::vector<std::string> to_string_vector(const Seq& seq) {
  std::vector<std::string> out;
  for (uint32_t i = 0; i < seq._length; ++i) out.push_back(to_string(seq._buffer[i]));
  return out;
}

}  // namespace rigger::dds
