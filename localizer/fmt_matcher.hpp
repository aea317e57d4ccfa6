#pragma once
// The `fmt` baseline of the paper's Tables II-III: curb map matching by the Fourier-Mellin transform
// on grid images (the paper's ref. [36]; the method is Reddy & Chatterji's FFT registration). Both the
// detected curbs and the map's curbs are drawn into 500 x 500 grids of 0.1 m cells (section 4.2.1,
// "according to ref [36]") centred on the prior position. The magnitude of an image's spectrum does
// not change when the image is shifted and turns with it when it is rotated, so phase correlation of
// the two magnitude spectra resampled on polar grids gives the rotation; phase correlation of the
// images, once the scan is turned back, gives the translation.
//
// The paper finds this unstable because curbs are sparse; so does this implementation on real scans.
// It is here as the comparison, not as a contender.
#include <vector>

#include <Eigen/Core>

#include "common/pose2d.hpp"

namespace lidarloop {

struct FmtParams {
  int size_cells = 500;  // grid images are size x size (section 4.2.1, ref. [36])
  double cell_m = 0.1;
  // Every point is splatted bilinearly (sub-cell positions survive), then blurred with this Gaussian
  // so that a curb line is a ridge a few cells wide rather than a string of isolated cells. It matters
  // for the rotation step, whose log-magnitude spectrum is not linear in the image; the translation
  // step's phase correlation whitens the spectra and so undoes a blur applied to both images alike,
  // which is one reason FMT suffers on sparse, noisy curbs. 1.5-2 cells did best on the tests'
  // junction: with 1 cell matches were lost at 0.08 m curb noise, with 3 the heading erred by 3 degrees.
  double blur_sigma_cells = 1.5;
  // Rotation step. Linear (not log-) polar resampling: both grids have the same cell size, so the
  // scale is known and log-polar's radial axis (scale -> shift) would carry nothing, while crowding
  // the samples into the low frequencies where the rotation is least well resolved.
  // The polar grid spans a half turn only: a real image's magnitude spectrum is symmetric through its
  // centre, so a full circle is two copies and its odd angular harmonics are zero. Phase correlation
  // whitens every harmonic to the same weight, so those zeros (rounding noise) would get half the
  // vote: with a full circle the rotation was wrong by 15-120 degrees on the tests' junction.
  // 0.5 degree bins; phaseCorrelate's sub-bin centroid brings the error to about 0.2 degree there.
  int angle_bins = 360;
  // Band of spatial frequencies used, as fractions of the Nyquist radius (size / 2 bins). Below: the
  // DC and the envelope of the Hanning window, the same in both spectra whatever the rotation. Above:
  // frequencies the Gaussian splat has all but removed (at sigma = 1.5 cells the spectrum is down to
  // e^-2 at 0.42 of Nyquist), i.e. noise.
  double min_radius_fraction = 0.04;
  double max_radius_fraction = 0.5;
  // Fewer usable points (finite and on the grid) than this in either set: no match. A handful of
  // points cannot make a spectrum whose rotation means anything.
  int min_points = 10;
  // phaseCorrelate's response is the normalised cross-power energy in the 5 x 5 cells around the peak
  // (1 = identical images up to a shift). Measured against the tests' junction: random scatter and a
  // roundabout score 0.01-0.07, the junction's own curbs 0.6-0.75 (0.03 m noise, every second point)
  // and down to 0.3-0.4 with 0.1 m noise or a fifth of the points. Not a safeguard against a wrong
  // match of plausible geometry: another straight road, turned 45 degrees onto the main road, scores
  // 0.4-0.6.
  double min_response = 0.1;
};

struct FmtResult {
  bool ok = false;  // false: too few points, or the translation peak below min_response
  // Maps the curbs (placed in the world at the prior pose) onto the map: the same meaning as
  // IcpResult::t, so the corrected pose is correction applied to the prior pose. Identity when !ok.
  Pose2d correction;
  double response = 0;  // phaseCorrelate peak response of the translation step (0 when not computed)
};

// curbs_world: detected curb features already placed in the local world frame with the prior pose;
// map_curbs: map curb points (local frame) around the prior; centre: the prior position, the centre of
// both grids and of the rotation. Points not finite or off the grid (+-25 m by default) are skipped.
// The translation found is at most half the grid (phase correlation is circular); the rotation is
// any angle (both readings of the magnitude spectrum's 180-degree ambiguity are tried).
// Throws std::invalid_argument if a parameter is out of range.
FmtResult fmt_match(const std::vector<Eigen::Vector2d>& curbs_world, const std::vector<Eigen::Vector2d>& map_curbs,
                    const Eigen::Vector2d& centre, const FmtParams& params = {});

}  // namespace lidarloop
