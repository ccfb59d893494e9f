#include "sim/cloth/grid_multigrid.h"

#include <Eigen/LU>
#include <algorithm>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace kf {

namespace {

constexpr double kOmega = 0.8;    // Jacobi damping: below 2 / rho(D^-1 A) (about 2 for these stencils); 0.8
                                  // took fewer CG iterations than 0.6 from 32^2 to 128^2
constexpr int kSweeps = 1;        // smoothing sweeps before and after the coarse correction (V(1,1):
                                  // fewer block products per CG iteration than V(2,2) for the same time)
constexpr int kCoarsest = 64;     // a level with at most this many nodes is solved exactly
constexpr int kRowGrain = 256;    // below this many rows a loop runs serially (a task costs more)

template <class F>
void for_rows(int n, const F& f) {
  if (n < 2 * kRowGrain) {
    for (int i = 0; i < n; ++i) f(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kRowGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) f(i);
  }, tbb::static_partitioner());
}

// Nodes of the coarser line: every other one and the last.
int coarse_count(int n) { return n % 2 ? (n + 1) / 2 : n / 2 + 1; }

// Linear interpolation along one grid line: fine index i from coarse nodes (index, weight).
std::vector<std::vector<std::pair<int, double>>> line_weights(int n) {
  const int nc = coarse_count(n);
  auto pos = [&](int k) { return std::min(2 * k, n - 1); };
  std::vector<std::vector<std::pair<int, double>>> w(n);
  for (int k = 0; k + 1 < nc; ++k) {
    const int a = pos(k), b = pos(k + 1);
    for (int i = a; i < b; ++i) {
      const double t = double(i - a) / (b - a);
      w[i].push_back({k, 1 - t});
      if (t > 0) w[i].push_back({k + 1, t});
    }
  }
  w[n - 1] = {{nc - 1, 1.0}};
  return w;
}

// Interpolation rows of an nx x ny grid from its coarser grid; an inactive fine node takes nothing (P's
// Dirichlet rows). coarse_active: 1 on every coarse node some active fine node takes from.
WeightedRows interpolation(int nx, int ny, const std::vector<char>& active, std::vector<char>& coarse_active) {
  const int cx = coarse_count(nx), cy = coarse_count(ny);
  const auto wx = line_weights(nx), wy = line_weights(ny);
  std::vector<std::vector<std::pair<int, double>>> parents(nx * ny);
  coarse_active.assign(cx * cy, 0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (active[j * nx + i])
        for (auto [cj, vj] : wy[j])
          for (auto [ci, vi] : wx[i]) {
            parents[j * nx + i].push_back({cj * cx + ci, vi * vj});
            coarse_active[cj * cx + ci] = 1;
          }
  return WeightedRows::from(parents);
}

// Restriction: the transpose of P, gathered per coarse node in fine order.
WeightedRows transposed(const WeightedRows& P, int nc) {
  std::vector<std::vector<std::pair<int, double>>> gather(nc);
  for (int i = 0; i + 1 < int(P.start.size()); ++i)
    for (int k = P.start[i]; k < P.start[i + 1]; ++k) gather[P.index[k]].push_back({i, P.w[k]});
  return WeightedRows::from(gather);
}

// Coarse pattern: (I, J) wherever a fine block (i, j) links a parent of i to a parent of j.
std::vector<std::vector<int>> coarse_pattern(const BlockSparse3& Af, const WeightedRows& P, int nc) {
  std::vector<std::vector<int>> cols(nc);
  for (int c = 0; c < nc; ++c) cols[c].push_back(c);
  for (int i = 0; i + 1 < int(P.start.size()); ++i)
    for (int s = Af.row_start(i); s < Af.row_start(i + 1); ++s) {
      const int j = Af.col(s);
      for (int a = P.start[i]; a < P.start[i + 1]; ++a)
        for (int b = P.start[j]; b < P.start[j + 1]; ++b) cols[P.index[a]].push_back(P.index[b]);
    }
  return cols;
}

// Galerkin lists: per coarse slot, the fine slots and weights w_iI w_jJ that sum into it.
WeightedRows galerkin_lists(const BlockSparse3& Af, const WeightedRows& P, const BlockSparse3& Ac) {
  std::vector<std::vector<std::pair<int, double>>> terms(Ac.nonzero_blocks());
  for (int i = 0; i + 1 < int(P.start.size()); ++i)
    for (int s = Af.row_start(i); s < Af.row_start(i + 1); ++s) {
      const int j = Af.col(s);
      for (int a = P.start[i]; a < P.start[i + 1]; ++a)
        for (int b = P.start[j]; b < P.start[j + 1]; ++b)
          terms[Ac.find(P.index[a], P.index[b])].push_back({s, P.w[a] * P.w[b]});
    }
  return WeightedRows::from(terms);
}

}  // namespace

WeightedRows WeightedRows::from(const std::vector<std::vector<std::pair<int, double>>>& rows) {
  WeightedRows r;
  for (const auto& row : rows) {
    for (auto [i, w] : row) {
      r.index.push_back(i);
      r.w.push_back(w);
    }
    r.start.push_back(int(r.index.size()));
  }
  return r;
}

void GridMultigrid::setup(int nx, int ny, const BlockSparse3& A, const std::vector<char>& free) {
  levels_.clear();
  levels_.emplace_back();
  levels_[0].nx = nx;
  levels_[0].ny = ny;
  levels_[0].active = free;
  while (levels_.back().nx * levels_.back().ny > kCoarsest && std::min(levels_.back().nx, levels_.back().ny) > 2) {
    Level& f = levels_.back();
    const BlockSparse3& Af = levels_.size() == 1 ? A : f.A_own;
    Level c;
    c.nx = coarse_count(f.nx);
    c.ny = coarse_count(f.ny);
    f.interp = interpolation(f.nx, f.ny, f.active, c.active);
    f.restriction = transposed(f.interp, c.nx * c.ny);
    c.A_own.set_pattern(coarse_pattern(Af, f.interp, c.nx * c.ny));
    f.galerkin = galerkin_lists(Af, f.interp, c.A_own);
    levels_.push_back(std::move(c));
  }
  for (Level& l : levels_) {
    const int n = l.nx * l.ny;
    l.inv_diag.assign(n, Mat3::Zero());
    l.r.setZero(3 * n);
    l.e.setZero(3 * n);
    l.t.setZero(3 * n);
  }
  const int nc = levels_.back().nx * levels_.back().ny;
  coarse_dense_.setZero(3 * nc, 3 * nc);
  coarse_rhs_.setZero(3 * nc);
}

bool GridMultigrid::prepare(const BlockSparse3& A) {
  for (int l = 0; l + 1 < levels(); ++l) {
    const Level& f = levels_[l];
    const BlockSparse3& Af = op(l, A);
    Level& c = levels_[l + 1];
    for_rows(c.nx * c.ny, [&](int I) {
      for (int s = c.A_own.row_start(I); s < c.A_own.row_start(I + 1); ++s) {
        Mat3 sum = Mat3::Zero();
        const WeightedRows& G = f.galerkin;
        for (int k = G.start[s]; k < G.start[s + 1]; ++k) sum += G.w[k] * Af.block(G.index[k]);
        c.A_own.block(s) = sum;
      }
      if (!c.active[I]) c.A_own.block(c.A_own.diag_slot(I)).setIdentity();  // a node with only pinned children
    });
  }
  bool ok = true;
  for (int l = 0; l < levels(); ++l) {
    Level& L = levels_[l];
    const BlockSparse3& Al = op(l, A);
    for (int i = 0; i < L.nx * L.ny; ++i) {
      if (!L.active[i]) {
        L.inv_diag[i].setZero();
        continue;
      }
      const Mat3& d = Al.block(Al.diag_slot(i));
      Eigen::LLT<Mat3> llt(d);
      if (llt.info() != Eigen::Success) ok = false;
      L.inv_diag[i] = kOmega * d.inverse();
    }
  }
  // The coarsest level, dense.
  const Level& last = levels_.back();
  const BlockSparse3& Ac = op(levels() - 1, A);
  coarse_dense_.setZero();
  for (int i = 0; i < last.nx * last.ny; ++i) {
    if (!last.active[i]) {
      coarse_dense_.block<3, 3>(3 * i, 3 * i).setIdentity();
      continue;
    }
    for (int s = Ac.row_start(i); s < Ac.row_start(i + 1); ++s)
      if (last.active[Ac.col(s)]) coarse_dense_.block<3, 3>(3 * i, 3 * Ac.col(s)) = Ac.block(s);
  }
  coarse_llt_.compute(coarse_dense_);
  return ok && coarse_llt_.info() == Eigen::Success;
}

// e = e + omega D^-1 (r - A e) on active rows (from_zero: e = omega D^-1 r).
void GridMultigrid::smooth(int l, const BlockSparse3& A, bool from_zero) {
  Level& L = levels_[l];
  if (from_zero) {
    for_rows(L.nx * L.ny, [&](int i) { seg(L.e, i).noalias() = L.inv_diag[i] * seg(L.r, i); });
    return;
  }
  for_rows(L.nx * L.ny, [&](int i) {
    seg(L.t, i) = L.active[i] ? Vec3(seg(L.e, i) + L.inv_diag[i] * (seg(L.r, i) - A.row_times(i, L.e))) : Vec3::Zero();
  });
  L.e.swap(L.t);
}

void GridMultigrid::cycle(int l, const BlockSparse3& fine) {
  Level& L = levels_[l];
  if (l == levels() - 1) {
    coarse_rhs_ = L.r;
    for (int i = 0; i < L.nx * L.ny; ++i)
      if (!L.active[i]) seg(coarse_rhs_, i).setZero();
    L.e = coarse_llt_.solve(coarse_rhs_);
    return;
  }
  const BlockSparse3& A = op(l, fine);
  smooth(l, A, true);
  for (int s = 1; s < kSweeps; ++s) smooth(l, A, false);
  // Residual, restricted to the next level.
  for_rows(L.nx * L.ny, [&](int i) {
    seg(L.t, i) = L.active[i] ? Vec3(seg(L.r, i) - A.row_times(i, L.e)) : Vec3::Zero();
  });
  Level& C = levels_[l + 1];
  for_rows(C.nx * C.ny, [&](int c) {
    Vec3 sum = Vec3::Zero();
    const WeightedRows& R = L.restriction;
    for (int k = R.start[c]; k < R.start[c + 1]; ++k) sum += R.w[k] * seg(L.t, R.index[k]);
    seg(C.r, c) = sum;
  });
  cycle(l + 1, fine);
  for_rows(L.nx * L.ny, [&](int i) {
    const WeightedRows& P = L.interp;
    for (int k = P.start[i]; k < P.start[i + 1]; ++k) seg(L.e, i) += P.w[k] * seg(C.e, P.index[k]);
  });
  for (int s = 0; s < kSweeps; ++s) smooth(l, A, false);
}

void GridMultigrid::apply(const BlockSparse3& A, const VecX& r, VecX& z) {
  levels_[0].r = r;
  cycle(0, A);
  z = levels_[0].e;
}

}  // namespace kf
