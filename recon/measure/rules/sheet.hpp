// Where the landmark rules write what they find: the landmarks (each with the
// mesh's confidence where it lies), the measurements with the geometry to draw,
// the measurements skipped and why, and the posture as the rules read it. Every
// position is in the body's frame (rules/body_cuts.hpp).
#pragma once

#include <Eigen/Core>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include "recon/geometry/triangle_mesh.hpp"
#include "recon/measure/body_measurements.hpp"
#include "recon/measure/surface_path.hpp"

namespace bodyscan::rules {

class MeasurementSheet {
 public:
  // Writes into *out. The surface-path structures (a tenth of the work, needed only
  // by the lengths at the end) are built on a thread of their own from here on.
  MeasurementSheet(const TriangleMesh& body, BodyMeasurements* out);
  MeasurementSheet(const MeasurementSheet&) = delete;
  MeasurementSheet& operator=(const MeasurementSheet&) = delete;

  void landmark(const std::string& name, const Eigen::Vector3d& p);
  // A landmark recorded before (the rules run in an order that guarantees it).
  Eigen::Vector3d position(const std::string& landmark) const;
  BodyPosture& posture() { return out_->posture; }
  // The last measurement recorded, if it is `name` (to adjust what a helper made).
  BodyMeasurement* last(const std::string& name);

  void skip(const std::string& name, const std::string& why);
  // A height: the level of p above the floor (Y = 0), drawn as a plumb line up to p.
  void height(const std::string& name, const std::string& label, const std::string& clause,
              std::vector<std::string> landmarks, const Eigen::Vector3d& p, const std::string& definition);
  // A girth from its tape, or skipped with the tape's error.
  void girth(const std::string& name, const std::string& label, const std::string& clause, const StatusOr<Girth>& g,
             std::vector<std::string> landmarks, const std::string& definition);
  // A length over the skin through `via`, the shortest path leg by leg.
  void surface(const std::string& name, const std::string& label, const std::string& clause,
               const std::vector<Eigen::Vector3d>& via, std::vector<std::string> landmarks,
               const std::string& definition);
  // A measurement made by hand; it inherits its landmarks' lowest confidence.
  void add(BodyMeasurement m);

 private:
  const TriangleMesh& body_;
  BodyMeasurements* out_;
  std::optional<SurfacePaths> paths_;
  // paths_ is being made: waited for before its first use, or (this future is
  // destroyed before paths_, and an async future waits) at the latest on leaving.
  std::future<void> paths_ready_;
};

}  // namespace bodyscan::rules
