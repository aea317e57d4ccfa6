#pragma once
// The localizer methods by name: the paper's and the baselines of its Tables II and III. Scenarios,
// the command line and the localizer all take these names, so the list lives here, once.
#include <string>
#include <vector>

namespace lidarloop {

// Every method runs in the same filter (prediction from CAN, KF1 with GPS); they differ in the
// map-matching observations of KF2:
//   gps        none
//   icp        plain ICP on the curb features, no obstacle removal (corridor, plane, d_o all off)
//   icp-obs    plain ICP on curb features after obstacle removal
//   m-icp      biweight M-ICP (Eq. 21-22) after obstacle removal
//   fmt        Fourier-Mellin on curb grid images after obstacle removal
//   intensity  APS on the intensity layer only
//   proposed   probabilistic ICP after obstacle removal, and APS
//   gicp       beyond the paper, a modern dense peer: Generalized-ICP (Open3D) of the whole de-skewed
//              scan against the map's point-cloud layer, an (x, y, psi) observation; no curbs, no paint
enum class LocalizerMethod { gps, icp, icp_obs, m_icp, fmt, intensity, proposed, gicp };

// In the enum's order.
const std::vector<std::string>& localizer_method_names();
std::string method_name(LocalizerMethod m);
// "gps, icp, ..., proposed", for help texts and error messages.
std::string method_name_list();
// Throws std::invalid_argument naming the method and listing the valid names.
LocalizerMethod parse_localizer_method(const std::string& name);

}  // namespace lidarloop
