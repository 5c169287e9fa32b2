#include "bindings.hpp"
#include "snakehead/limits.hpp"

namespace py = pybind11;

namespace snakehead::bindings {
namespace {

// A name for the class that holds the limits; never instantiated (no constructor is bound).
struct LimitsTag {};

}  // namespace

void bind_limits(py::module_& m) {
  // The core's limits (include/snakehead/limits.hpp), read by Python (snakehead.limits) instead of repeated there.
  py::class_<LimitsTag> c(m, "Limits",
                          "The C++ core's limits on what callers may ask for (include/snakehead/limits.hpp), as "
                          "class attributes; snakehead.limits gives them their Python names.");
  c.attr("MAX_TIMEOUT_S") = limits::kMaxTimeoutSeconds;
  c.attr("MAX_URDF_BYTES") = limits::kMaxUrdfBytes;
  c.attr("MAX_URDF_DEPTH") = limits::kMaxUrdfDepth;
  c.attr("MAX_IK_JOINTS") = limits::kMaxIKJoints;
  c.attr("MAX_VOXELS_PER_AXIS") = limits::kMaxVoxelsPerAxis;
  c.attr("MAX_DIRECTIONS") = limits::kMaxDirections;
  c.attr("MAX_ROLLS") = limits::kMaxRolls;
  c.attr("MAX_FRAMES_PER_VOXEL") = limits::kMaxFramesPerVoxel;
  c.attr("MAX_CLOUD_SAMPLES") = limits::kMaxCloudSamples;
  c.attr("MAX_THREADS") = limits::kMaxThreads;
  c.attr("MAX_TERRAIN_CELLS") = limits::kMaxTerrainCells;
  c.attr("MAX_TERRAIN_TRIANGLES") = limits::kMaxTerrainTriangles;
}

}  // namespace snakehead::bindings
