// The small robot the path-check and tracking-fit tests share: a four-joint chain (yaw, pitch, yaw, pitch) of
// 0.1 m links l1..l4 from l0, each carrying a box (box_length x 0.04 x 0.04 m) centred 0.05 m along its x axis.
#pragma once

#include <string>
#include <vector>

#include "snakehead/model.hpp"
#include "snakehead/shape_set.hpp"

namespace snakehead::test {

inline std::string four_link_chain_urdf(double box_length) {
  const std::string box = "<collision><origin xyz='0.05 0 0'/><geometry><box size='" + std::to_string(box_length) +
                          " 0.04 0.04'/></geometry></collision>";
  std::string s = "<robot name='c'><link name='l0'/>";
  const char* axes[] = {"0 0 1", "0 1 0", "0 0 1", "0 1 0"};
  for (int j = 0; j < 4; ++j) {
    const std::string me = "l" + std::to_string(j + 1), parent = "l" + std::to_string(j);
    s += "<link name='" + me + "'>" + box + "</link>";
    s += "<joint name='j" + std::to_string(j) + "' type='revolute'><parent link='" + parent + "'/><child link='" +
         me + "'/><origin xyz='" + (j == 0 ? "0" : "0.1") + " 0 0'/><axis xyz='" + axes[j] +
         "'/><limit lower='-3' upper='3' effort='1' velocity='1'/></joint>";
  }
  return s + "</robot>";
}

inline ChainModel four_link_chain(double box_length) {
  return ChainModel::from_urdf(four_link_chain_urdf(box_length), "l0", "l4");
}

// The boxes of four_link_chain_urdf as the geometry layer's shapes, one per link.
inline std::vector<ConvexShape> four_link_boxes(const ChainModel& model, double box_length) {
  std::vector<ConvexShape> out;
  for (int k = 1; k <= 4; ++k) {
    ConvexShape s;
    s.kind = ShapeKind::Box;
    s.frame = model.link_index("l" + std::to_string(k));
    s.origin.translation() = Eigen::Vector3d(0.05, 0.0, 0.0);
    s.size = Eigen::Vector3d(box_length, 0.04, 0.04);
    out.push_back(s);
  }
  return out;
}

}  // namespace snakehead::test
