#include "recon/measure/body_posture.hpp"

#include <cmath>
#include <cstdio>

namespace bodyscan {

namespace {

std::string degrees(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0f°", x);
  return b;
}

std::string millimetres(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0f mm", x);
  return b;
}

// "35–50°", "300–450 mm"
std::string range(double lo, double hi, const char* unit) {
  char b[48];
  std::snprintf(b, sizeof b, "%.0f–%.0f%s", lo, hi, unit);
  return b;
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

std::vector<PostureCheck> check_posture(const BodyPosture& p, const PostureRange& r) {
  std::vector<PostureCheck> out;
  for (int s = 0; s < 2; ++s) {
    const std::string side = s == 0 ? "left" : "right";
    if (p.arm_against_body[s]) {
      out.push_back({"arm_" + side, false,
                     "the " + side + " arm rests against the body: hold it " +
                         range(r.arm_min_deg, r.arm_max_deg, "°") + " from the body"});
      continue;
    }
    if (!p.arm_abduction_deg[s]) continue;
    const double a = *p.arm_abduction_deg[s];
    PostureCheck c{"arm_" + side, a >= r.arm_min_deg && a <= r.arm_max_deg, ""};
    if (a < r.arm_min_deg)
      c.message = "the " + side + " arm hangs " + degrees(a) + " from the body: raise it to " +
                  range(r.arm_min_deg, r.arm_max_deg, "°");
    else if (a > r.arm_max_deg)
      c.message = "the " + side + " arm is held " + degrees(a) + " from the body: lower it to " +
                  range(r.arm_min_deg, r.arm_max_deg, "°");
    out.push_back(c);
  }
  if (p.ankle_distance_mm) {
    const double d = *p.ankle_distance_mm;
    PostureCheck c{"feet", d >= r.ankles_min_mm && d <= r.ankles_max_mm, ""};
    if (!c.ok)
      c.message = "the ankles are " + millimetres(d) + " apart: stand with them " +
                  range(r.ankles_min_mm, r.ankles_max_mm, " mm") + " apart";
    out.push_back(c);
  }
  if (p.head_tilt_deg && p.head_side_tilt_deg) {
    const double f = *p.head_tilt_deg, l = *p.head_side_tilt_deg;
    PostureCheck c{"head", std::abs(f) <= r.head_max_deg && std::abs(l) <= r.head_max_deg, ""};
    if (!c.ok)
      c.message = std::string("the head is tilted ") +
                  (std::abs(f) >= std::abs(l) ? degrees(std::abs(f)) + (f > 0 ? " forward" : " back")
                                              : degrees(std::abs(l)) + (l > 0 ? " to the left" : " to the right")) +
                  ": look straight ahead";
    out.push_back(c);
  }
  PostureCheck t{"turn", std::abs(p.turn_deg) <= r.turn_max_deg, ""};
  if (!t.ok) t.message = "the body faces " + degrees(p.turn_deg) + " from the rig's front: turn to face it";
  out.push_back(t);
  return out;
}

std::vector<std::string> posture_parts(const std::string& m) {
  // Where the arms meet the trunk: the shoulder points, the armpits' vault and the
  // side neck points move with the arms.
  if (m == "shoulder_width" || m == "biacromial_breadth" || m == "chest_girth" || m == "bust_girth" ||
      m == "neck_base_girth")
    return {"arm_left", "arm_right"};
  for (const char* side : {"left", "right"}) {
    const std::string s = side;
    if (m == "outer_arm_length_" + s || m == "upper_arm_girth_" + s) return {"arm_" + s};
  }
  // The stance moves the hips and thighs, and with the legs' slant every height.
  if (m == "hip_girth" || m == "max_hip_girth" || starts_with(m, "thigh_girth_") ||
      starts_with(m, "mid_thigh_girth_") || starts_with(m, "knee_girth_") || m == "stature" ||
      starts_with(m, "crotch_height") || m == "hip_height" || starts_with(m, "knee_height_"))
    return {"feet"};
  // The back neck point is read at the side neck points' level. The under-bust is
  // sought below the bust, which is sought below the armpits; the waist between the
  // hip (above the crotch) and the under-bust: on a scan, where hole filling moves
  // an armpit or the crotch, their levels move with it.
  if (m == "cervical_height" || m == "waist_height" || m == "underbust_girth" || m == "waist_girth" ||
      m == "back_neck_to_waist")
    return {"feet", "arm_left", "arm_right"};
  return {};
}

std::string posture_assumed(const std::string& m, const PostureRange& r) {
  std::string arms, feet;
  for (const std::string& part : posture_parts(m)) {
    if (starts_with(part, "arm")) arms = (arms.empty() ? "" : arms + " and ") + part.substr(4);
    if (part == "feet") feet = "the ankles " + range(r.ankles_min_mm, r.ankles_max_mm, " mm") + " apart";
  }
  std::string out;
  if (!arms.empty())
    out = (arms == "left and right" ? std::string("the arms") : "the " + arms + " arm") + " " +
          range(r.arm_min_deg, r.arm_max_deg, "°") + " from the vertical";
  if (!feet.empty()) out += (out.empty() ? "" : ", ") + feet;
  return out;
}

}  // namespace bodyscan
