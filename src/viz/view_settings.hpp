#pragma once
// How often the live view reads and sends each part (settings file section `view:`). The
// point cloud is the heavy part: 10,000 points are 160 KB as PointCloud2.
namespace hiveslam::viz {

struct ViewSettings {
  double pose_hz = 30;     // PoseStamped and TF: at most this often (every frame at 30 Hz)
  double path_hz = 2;      // Path
  double cloud_hz = 2;     // PointCloud2 and MarkerArray (the bound: at most 2 Hz)
  double status_hz = 1;    // the node panel (std_msgs/String JSON) and its events
  double image_hz = 5;     // the web page's camera image (JPEG)
  int web_kbytes_per_s = 300;  // the web page's push budget per client: map updates wait for it
};

}  // namespace hiveslam::viz
