#pragma once
// Superelevation through curves (AASHTO "A Policy on Geometric Design of Highways and Streets",
// 2011, 3.3: low-speed urban streets). A curve whose design speed needs more side force than the
// tyres give on a crowned road is banked towards its inside; the bank is reached and left over a
// runoff whose length keeps the edge's grade relative to the centreline within a maximum.
#include <vector>

#include "sim/polyline.hpp"

namespace lidarloop {

// Side friction factor for low-speed urban streets at a design speed (km/h): AASHTO 2011 Fig. 3-6,
// read from the figure (quoted from memory, to 0.01).
double low_speed_side_friction(double speed_kmh);

// Maximum relative gradient of the pavement edge to the axis of rotation, -/-: AASHTO 2011 Table 3-15
// (quoted from memory).
double max_relative_gradient(double speed_kmh);

// The bank a curve of `radius` needs at `speed_kmh` (AASHTO's low-speed method: e = V^2 / (127 R) - f),
// 0 when the normal crown will do, else at least `cross_slope` (the adverse crown removed) and at most
// `max_rate`.
double superelevation_rate(double radius, double speed_kmh, double cross_slope, double max_rate);

// The signed bank along a centreline at arc lengths `s` (ascending): positive where the road curves
// left (its left side is the inside, and lower), ramped in and out at the maximum relative gradient over
// `half_width`.
std::vector<double> superelevation_profile(const Polyline2d& centreline, bool closed, const std::vector<double>& s,
                                           double speed_kmh, double cross_slope, double max_rate, double half_width);

// Height of the carriageway `lateral` metres left of the centreline below it, for a crown of
// `cross_slope` and a signed bank `e` part-way or fully developed: the outside half turns from falling
// at the crown's slope to rising at the bank's, the inside half falls at the larger of the two.
double banked_section(double lateral, double cross_slope, double e);

}  // namespace lidarloop
