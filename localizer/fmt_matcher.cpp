#include "localizer/fmt_matcher.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace lidarloop {

namespace {

// Smallest grid accepted: phaseCorrelate takes a 5 x 5 centroid around its peak, and a spectrum of a
// few cells has no angular resolution to speak of. Largest: a typo must not allocate gigabytes (a
// 4096-cell grid is 64 MB per float image; the paper's is 500).
constexpr int kMinSizeCells = 16, kMaxSizeCells = 4096;
constexpr int kMinAngleBins = 8, kMaxAngleBins = 36000;  // up to 0.005 degree bins

void validate(const FmtParams& p) {
  if (p.size_cells < kMinSizeCells || p.size_cells > kMaxSizeCells)
    throw std::invalid_argument("fmt_match: size_cells must be 16 to 4096");
  if (!(p.cell_m > 0) || !std::isfinite(p.cell_m)) throw std::invalid_argument("fmt_match: cell_m must be > 0");
  if (!(p.blur_sigma_cells >= 0) || !std::isfinite(p.blur_sigma_cells))
    throw std::invalid_argument("fmt_match: blur_sigma_cells must be >= 0");
  if (p.angle_bins < kMinAngleBins || p.angle_bins > kMaxAngleBins)
    throw std::invalid_argument("fmt_match: angle_bins must be 8 to 36000");
  if (!(p.min_radius_fraction >= 0) || !(p.max_radius_fraction <= 1) ||
      !(p.min_radius_fraction < p.max_radius_fraction))
    throw std::invalid_argument("fmt_match: need 0 <= min_radius_fraction < max_radius_fraction <= 1");
  if (p.min_points < 1) throw std::invalid_argument("fmt_match: min_points must be >= 1");
  if (!(p.min_response >= 0 && p.min_response <= 1))
    throw std::invalid_argument("fmt_match: min_response must be in [0, 1]");
}

// Image layout, as the driving corridor's grid: column = world x (grows to the right), row = -world y
// (row 0 is the northernmost strip). Pixel centres sit at integer coordinates and `centre` at the
// centre of pixel (size/2, size/2), which is also where the shifted spectrum has its DC term.
Eigen::Vector2d to_pixel(const Eigen::Vector2d& p, const Eigen::Vector2d& centre, const FmtParams& params) {
  const double half = params.size_cells / 2;
  return {(p.x() - centre.x()) / params.cell_m + half, -(p.y() - centre.y()) / params.cell_m + half};
}

// Bilinear splat of every point (sub-cell positions survive into the image), then the Gaussian blur of
// FmtParams::blur_sigma_cells. `rotation` (rad, world sense) turns the points about `centre` first.
// Returns the number of points that landed on the grid.
int rasterise(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& centre, double rotation,
              const FmtParams& params, cv::Mat& image) {
  const int n = params.size_cells;
  image = cv::Mat::zeros(n, n, CV_32F);
  const double c = std::cos(rotation), s = std::sin(rotation);
  int used = 0;
  for (const auto& p : points) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) continue;
    const Eigen::Vector2d d = p - centre;
    const Eigen::Vector2d q =
        to_pixel(centre + Eigen::Vector2d(c * d.x() - s * d.y(), s * d.x() + c * d.y()), centre, params);
    // All four bilinear neighbours must be on the grid; a point on the outermost half cell is dropped.
    if (!(q.x() >= 0 && q.y() >= 0 && q.x() < n - 1 && q.y() < n - 1)) continue;
    const int col = static_cast<int>(q.x()), row = static_cast<int>(q.y());
    const float fx = static_cast<float>(q.x() - col), fy = static_cast<float>(q.y() - row);
    image.at<float>(row, col) += (1 - fx) * (1 - fy);
    image.at<float>(row, col + 1) += fx * (1 - fy);
    image.at<float>(row + 1, col) += (1 - fx) * fy;
    image.at<float>(row + 1, col + 1) += fx * fy;
    ++used;
  }
  if (params.blur_sigma_cells > 0)
    cv::GaussianBlur(image, image, cv::Size(0, 0), params.blur_sigma_cells, params.blur_sigma_cells,
                     cv::BORDER_CONSTANT);
  return used;
}

// Circular shift by size/2 along both axes, so the DFT's zero frequency lands on pixel (size/2,
// size/2) (the usual fftshift; also right for odd sizes, where a plain quadrant swap is not).
cv::Mat fft_shift(const cv::Mat& m) {
  const int n = m.rows, h = n / 2;
  cv::Mat rows(m.size(), m.type()), out(m.size(), m.type());
  m.rowRange(0, n - h).copyTo(rows.rowRange(h, n));
  m.rowRange(n - h, n).copyTo(rows.rowRange(0, h));
  rows.colRange(0, n - h).copyTo(out.colRange(h, n));
  rows.colRange(n - h, n).copyTo(out.colRange(0, h));
  return out;
}

// log(1 + |DFT(image * window)|), zero frequency at the centre, resampled on a linear polar grid:
// row = angle (angle_bins over a half turn, measured from +column towards +row), column = radius in
// frequency bins, cropped to the band of FmtParams::min/max_radius_fraction. The Hanning window keeps
// the grid's border (curbs cut off by it) from drawing a bright cross through the spectrum that does
// not turn with the scene and would pull every rotation towards zero. The log keeps the few strongest
// frequencies (the direction of the main road) from deciding alone (measured: without it the heading
// error on the test junction doubles).
cv::Mat polar_spectrum(const cv::Mat& image, const cv::Mat& window, const FmtParams& params) {
  cv::Mat spectrum;
  cv::dft(image.mul(window), spectrum, cv::DFT_COMPLEX_OUTPUT);
  std::array<cv::Mat, 2> parts;
  cv::split(spectrum, parts.data());
  cv::Mat magnitude;
  cv::magnitude(parts[0], parts[1], magnitude);
  magnitude += 1;
  cv::log(magnitude, magnitude);
  magnitude = fft_shift(magnitude);

  // warpPolar always spans the full circle; the second half turn repeats the first (see
  // FmtParams::angle_bins), so sample twice as many angles and keep the first half.
  const int radius_bins = params.size_cells / 2;  // one polar column per frequency bin out to Nyquist
  const float dc = static_cast<float>(params.size_cells / 2);
  cv::Mat polar;
  cv::warpPolar(magnitude, polar, cv::Size(radius_bins, 2 * params.angle_bins), cv::Point2f(dc, dc), radius_bins,
                static_cast<int>(cv::INTER_LINEAR) | static_cast<int>(cv::WARP_POLAR_LINEAR));
  const int r_min = static_cast<int>(std::floor(params.min_radius_fraction * radius_bins));
  const int r_max = static_cast<int>(std::ceil(params.max_radius_fraction * radius_bins));
  return polar(cv::Range(0, params.angle_bins), cv::Range(r_min, r_max)).clone();  // phaseCorrelate: continuous
}

}  // namespace

FmtResult fmt_match(const std::vector<Eigen::Vector2d>& curbs_world, const std::vector<Eigen::Vector2d>& map_curbs,
                    const Eigen::Vector2d& centre, const FmtParams& params) {
  validate(params);
  FmtResult result;
  if (!centre.allFinite()) return result;

  cv::Mat map_image, scan_image;
  if (rasterise(map_curbs, centre, 0, params, map_image) < params.min_points) return result;
  if (rasterise(curbs_world, centre, 0, params, scan_image) < params.min_points) return result;

  cv::Mat window;
  cv::createHanningWindow(window, map_image.size(), CV_32F);

  // Rotation. The map's spectrum is the scan's turned by the scan-to-map rotation: on the polar grids,
  // a circular shift along the angle rows. phaseCorrelate(a, b) returns d with b(x) = a(x - d), so d.y
  // rows from the scan's spectrum to the map's. Rows count angles from +column towards +row, which is
  // clockwise in the world (rows grow southwards): the world rotation is minus that.
  const cv::Point2d polar_shift =
      cv::phaseCorrelate(polar_spectrum(scan_image, window, params), polar_spectrum(map_image, window, params));
  if (!std::isfinite(polar_shift.y)) return result;
  const double rotation = -polar_shift.y * std::numbers::pi / params.angle_bins;

  // A real image's magnitude spectrum is symmetric through its centre, so the rotation is known only up
  // to 180 degrees: turn the scan both ways and keep the better translation peak.
  bool have = false;
  double best_response = 0, best_rotation = 0;
  cv::Point2d best_shift;
  for (const double candidate : {rotation, rotation + std::numbers::pi}) {
    rasterise(curbs_world, centre, candidate, params, scan_image);
    double response = 0;
    const cv::Point2d shift = cv::phaseCorrelate(scan_image, map_image, window, &response);
    if (!std::isfinite(response) || !std::isfinite(shift.x) || !std::isfinite(shift.y)) continue;
    if (!have || response > best_response) {
      have = true;
      best_response = response;
      best_rotation = wrap_angle(candidate);
      best_shift = shift;
    }
  }
  if (!have) return result;
  result.response = best_response;
  if (best_response < params.min_response) return result;

  // p -> R (p - centre) + centre + t: turn about the prior position, then shift. Pixel shift to metres:
  // columns are +x, rows are -y.
  const Eigen::Vector2d t(best_shift.x * params.cell_m, -best_shift.y * params.cell_m);
  const double c = std::cos(best_rotation), s = std::sin(best_rotation);
  const Eigen::Vector2d turned_centre(c * centre.x() - s * centre.y(), s * centre.x() + c * centre.y());
  const Eigen::Vector2d offset = centre - turned_centre + t;
  result.correction = Pose2d{offset.x(), offset.y(), best_rotation};
  result.ok = true;
  return result;
}

}  // namespace lidarloop
