#include "pipeline/repeat_scans.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <ctime>
#include <optional>
#include <string>

namespace bodyscan::pipeline {
namespace {

// Sets the process's time zone for one test and puts the old one back.
class TimeZone {
 public:
  explicit TimeZone(const char* tz) {
    if (const char* old = std::getenv("TZ")) old_ = old;
    setenv("TZ", tz, 1);
    tzset();
  }
  ~TimeZone() {
    if (old_)
      setenv("TZ", old_->c_str(), 1);
    else
      unsetenv("TZ");
    tzset();
  }

 private:
  std::optional<std::string> old_;
};

TEST(RepeatScans, TheSameDayIsTheWorkstationsLocalDay) {
  {
    TimeZone utc("UTC");
    EXPECT_TRUE(same_local_day("2026-11-29T00:10:00Z", "2026-11-29T23:50:00Z"));
    EXPECT_FALSE(same_local_day("2026-11-29T23:50:00Z", "2026-11-30T00:10:00Z"));
  }
  {
    // A shop an hour east of UTC (POSIX form, no zoneinfo needed): 23:50 UTC is
    // 00:50 the next day there.
    TimeZone berlin("CET-1");
    EXPECT_FALSE(same_local_day("2026-11-29T00:10:00Z", "2026-11-29T23:50:00Z"));
    EXPECT_TRUE(same_local_day("2026-11-29T23:50:00Z", "2026-11-30T10:00:00Z"));
  }
  EXPECT_FALSE(same_local_day("not a time", "2026-11-29T10:00:00Z"));
  // The archive's times carry milliseconds.
  EXPECT_TRUE(same_local_day("2026-11-29T10:00:00.123Z", "2026-11-29T11:00:00Z"));
  EXPECT_FALSE(same_local_day("2026-11-29T10:00:00.123", "2026-11-29T11:00:00Z"));
}

TEST(RepeatScans, TheToleranceIsTheShopsElseTheIsoAllowance) {
  storage::MeasurementRecord waist, wrist, stature, arm, shoulders;
  waist.name = "waist_girth", waist.kind = "girth";
  wrist.name = "wrist_girth_left", wrist.kind = "girth";
  stature.name = "stature", stature.kind = "height";
  arm.name = "outer_arm_length_left", arm.kind = "surface_length";
  shoulders.name = "biacromial_breadth", shoulders.kind = "distance";
  EXPECT_EQ(repeat_tolerance_mm(waist, 0), 9);
  EXPECT_EQ(repeat_tolerance_mm(wrist, 0), 4);
  EXPECT_EQ(repeat_tolerance_mm(stature, 0), 4);
  EXPECT_EQ(repeat_tolerance_mm(arm, 0), 5);
  EXPECT_EQ(repeat_tolerance_mm(shoulders, 0), 4);  // a body breadth
  EXPECT_EQ(repeat_tolerance_mm(waist, 2.5), 2.5);
}

}  // namespace
}  // namespace bodyscan::pipeline
