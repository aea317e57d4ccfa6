#pragma once
// Curb map matching (the paper's section 3.1): the detected curbs C are registered to the map's curb
// points M by point-to-point ICP (Eq. 9). Probabilistic ICP (Eq. 10-13) runs n_t "local" ICPs on random
// n_p-point subsets, refines each by a "global" ICP on all curbs that drops correspondences beyond d_g
// (Eq. 12), and fuses the refined transforms weighted by how few outliers each leaves (Eq. 13).
// M-ICP (Eq. 21-22, the robust baseline of Tables II-III) is here too, as a biweight IRLS ICP.
//
// Everything is a free function over plain Eigen types; randomness only from the engine passed in.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/pose2d.hpp"
#include "localizer/map_index.hpp"

namespace lidarloop {

// Closed-form weighted least-squares rigid fit minimising sum w_i |T src_i - dst_i|^2: the SVD step of
// the paper's ICP [43]. In 2-D the SVD of the 2x2 cross-covariance reduces to one atan2, which is exact
// and cannot produce a reflection. Null weights = all 1. Fewer than one usable pair -> identity; one
// pair -> pure translation.
Pose2d fit_rigid_2d(const std::vector<Eigen::Vector2d>& src, const std::vector<Eigen::Vector2d>& dst,
                    const std::vector<double>* weights = nullptr);

struct IcpParams {
  int max_iterations = 30;
  double convergence = 1e-4;        // stop when an update moves less than this (m and rad)
  double max_correspondence = 2.0;  // m; nearest neighbours farther than this are never paired
};

struct IcpResult {
  Pose2d t;
  double rmse = 0;           // m, over the final inliers
  int iterations = 0;        // ICP: updates made; probabilistic ICP: draws fused (n_t)
  double outlier_ratio = 1;  // fraction of curbs farther than the rejection distance from the map under t
  size_t inliers = 0;        // curbs within the rejection distance under t
};

// Point-to-point ICP (Eq. 9) from `initial`, nearest-neighbour correspondences re-found each iteration.
// Correspondences farther than min(max_correspondence, reject_distance) are dropped each iteration
// (with reject_distance = d_g this is Eq. 12); the same distance defines outliers in the result.
// Empty curbs or map: returns `initial` with outlier_ratio 1.
IcpResult icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Pose2d initial, const IcpParams& params,
              double reject_distance = std::numeric_limits<double>::infinity());

struct MIcpParams {
  IcpParams icp;
  // Tukey's biweight constant of Eq. 22 in units of `scale_m`. The paper prints 4.681; 4.685 is the
  // standard value giving 95 % efficiency under Gaussian residuals, which is what the paper says it wants.
  double biweight_b = 4.685;
  // The residual scale: Eq. 22 is for standardised residuals ("fits the normal distribution"), but the
  // paper never says how e of Eq. 21 (metres) is standardised. We use a fixed scale rather than the MAD
  // because with a large initial pose error the MAD is dominated by that error, not by curb noise. With
  // 0.3 m, residuals beyond 4.685 * 0.3 = 1.4 m get zero weight.
  double scale_m = 0.3;
};

// M-ICP baseline (Eq. 21-22): minimises sum rho(|T C_i - M| / scale) by iteratively reweighted least
// squares with the biweight weight w(u) = (1 - (u/B)^2)^2 for |u| < B, else 0 (rho'(u)/u of Eq. 22).
// Outliers in the result are curbs with zero weight (residual beyond B * scale).
IcpResult m_icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Pose2d initial,
                const MIcpParams& params);

struct ProbabilisticIcpParams {
  int n_p = 15;      // curbs drawn per local ICP (Table I)
  int n_t = 30;      // draws (Table I)
  double d_g = 1.0;  // m, Eq. 12 outlier distance of the global ICP (Table I)
  IcpParams local, global;
  // Eq. 13 weighting, our reading: eta_i is printed as "the ratio of outliers", but the stated intent is
  // that iterations with fewer outliers count more. We weight w_i = exp(-(n_out,i - n_out,min) / s), a
  // softmax over the outlier counts: the best draw has weight 1 and every further curb it leaves
  // unexplained costs a factor e^(1/s). Why so sharp: with d_g = 1 m a draw stuck 0.1-0.3 m off in a
  // neighbouring minimum still explains all but one or two curbs, so the outlier ratio separates draws
  // only at the level of single curbs; a linear (1 - eta) weight, or a softer one, lets such draws drag
  // the mean by centimetres (seen in tests: 4.5 cm with s = 8.6 curbs). Draws that converge to the same
  // minimum have the same count and are averaged evenly.
  double outlier_softness_curbs = 1.0;
};

// One draw's global-ICP result, as fused by Eq. 13.
struct IcpHypothesis {
  Pose2d t;
  double outlier_ratio = 1;
};

// Eq. 13 with our weighting (see ProbabilisticIcpParams::outlier_softness_curbs), the softness given as
// an outlier ratio (softness in curbs / number of curbs): w_i = exp(-(eta_i - eta_min) / temperature),
// then the weighted mean of x, y, and of theta as an angle (atan2 of the weighted sines and cosines).
// Temperature 0 keeps only the best draws. Empty input -> identity.
Pose2d fuse_hypotheses(const std::vector<IcpHypothesis>& hypotheses, double outlier_temperature);

// Probabilistic ICP (section 3.1). All n_t samples are drawn from `rng` up front in a fixed order, so
// the result depends only on the inputs and the engine state, and the draws could run in parallel.
// Fewer than n_p curbs: every draw is all curbs, so one draw is made. Empty curbs or map: `initial`
// with outlier_ratio 1. The result's outlier_ratio, inliers and rmse are those of the fused transform
// against d_g.
IcpResult probabilistic_icp(const MapIndex& map, const std::vector<Eigen::Vector2d>& curbs, Pose2d initial,
                            const ProbabilisticIcpParams& params, std::mt19937_64& rng);

}  // namespace lidarloop
