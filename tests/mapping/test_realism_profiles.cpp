// Realism profiles as the map sees them: typical is the default survey, ideal a survey that is the world,
// harsh a map made without RTK (GNSS-anchored SLAM, labelled curbs); each its own map in the cache.
#include <gtest/gtest.h>

#include "mapping/mapping_drive.hpp"
#include "sim/hdl32e.hpp"

namespace lidarloop {
namespace {

TEST(RealismProfiles, EachProfileSurveysItsOwnMap) {
  const MappingOptions ideal = mapping_options_for(Realism::ideal), typical = mapping_options_for(Realism::typical),
                       harsh = mapping_options_for(Realism::harsh);
  EXPECT_EQ(typical.describe(), MappingOptions{}.describe());  // typical maps keep the cache key they had
  EXPECT_EQ(ideal.survey_error.sigma_xy_m, 0.0);
  EXPECT_EQ(ideal.survey_error.heading_sigma_rad, 0.0);
  EXPECT_EQ(ideal.survey_unit_serial, Hdl32eConfig{}.unit_serial);  // the car's own unit
  EXPECT_TRUE(ideal.ideal_ground);
  // harsh: a GNSS-anchored SLAM map, its curbs labelled at the face's top with noise.
  EXPECT_EQ(typical.survey_error.provenance, MapProvenance::rtk_ins);
  EXPECT_EQ(harsh.survey_error.provenance, MapProvenance::slam);
  EXPECT_GT(harsh.survey_error.slam.absolute_sigma_m, typical.survey_error.sigma_xy_m);
  EXPECT_EQ(harsh.curb_label.convention, CurbLabel::face_top);
  EXPECT_GT(harsh.curb_label.noise_m, 0.0);
  EXPECT_TRUE(typical.curb_label.is_default());
  EXPECT_NE(ideal.describe(), typical.describe());
  EXPECT_NE(harsh.describe(), typical.describe());
}

// The survey's paint is in the map's cache key; the drive day's changes to it are not (the map is the same).
TEST(RealismProfiles, TheSurveysPaintIsInTheMapsCacheKey) {
  MappingOptions worn, uniform;
  uniform.paint.varied = false;
  EXPECT_NE(worn.describe(), uniform.describe());
  MappingOptions faded = worn;
  faded.paint.faded_fraction = 0.5;
  faded.paint.repainted_fraction = 0.3;
  EXPECT_EQ(faded.describe(), worn.describe());
  MappingOptions more_worn = worn;
  more_worn.paint.worn_fraction = 0.3;
  EXPECT_NE(more_worn.describe(), worn.describe());
  EXPECT_TRUE(mapping_options_for(Realism::harsh).paint.varied);
  EXPECT_TRUE(mapping_options_for(Realism::typical).paint.varied);
  EXPECT_FALSE(mapping_options_for(Realism::ideal).paint.varied);
}

TEST(RealismProfiles, TheIdealMapsWorldIsOnIdealGround) {
  const LoadedWorld typical = load_mapped_world("campus", mapping_options_for(Realism::typical));
  const LoadedWorld ideal = load_mapped_world("campus", mapping_options_for(Realism::ideal));
  // Campus's loop is crowned at 2 %: 3 m from its centre line the pavement is 6 cm lower, except on
  // ideal ground, where every road is flat.
  const GroundHeight typical_ground = typical.world.pavement(), ideal_ground = ideal.world.pavement();
  double typical_spread = 0, ideal_spread = 0;
  for (double y : {-3.0, -1.5, 0.0, 1.5, 3.0}) {
    typical_spread = std::max(typical_spread, std::abs(typical_ground({150, y}) - typical_ground({150, 0})));
    ideal_spread = std::max(ideal_spread, std::abs(ideal_ground({150, y}) - ideal_ground({150, 0})));
  }
  EXPECT_GT(typical_spread, 0.03);
  EXPECT_LT(ideal_spread, 1e-6);
}

}  // namespace
}  // namespace lidarloop
