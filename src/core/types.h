#pragma once
// Small numeric types shared by every layer. Simulation and gradients are double precision.
#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace kf {
using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;
using Mat3 = Eigen::Matrix3d;
using VecX = Eigen::VectorXd;  // stacked per-particle vectors: 3p entries, particle i at [3i, 3i+3)
using MatX = Eigen::MatrixXd;
using SpMat = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using Triplet = Eigen::Triplet<double>;

inline auto seg(VecX& v, int i) { return v.segment<3>(3 * i); }
inline auto seg(const VecX& v, int i) { return v.segment<3>(3 * i); }
}  // namespace kf
