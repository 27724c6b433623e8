#include "communication/security/grants.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "common/error.hpp"
#include "communication/message.hpp"

namespace hiveslam::communication::security {

namespace {

// Every domain a node can be started on (--domain 0-232).
constexpr const char* kDomains = "<domains><id_range><min>0</min><max>232</max></id_range></domains>";
constexpr const char* kNodes = "rt/hiveslam/nodes";  // the nodes' announcements (dds_transport.cpp)
constexpr const char* kCamera = "rt/camera/*";       // images: play --topic /camera/...

// The ROS 2 visualization topics a node writes (viz/ros/ros_viz_publisher.cpp).
constexpr const char* kVizTopics[] = {"pose", "tf", "path", "points", "keyframe_markers", "status"};

bool validName(const std::string& s) {
  // A letter first: a ROS name may not start with a digit (viz/ros/ros_messages.cpp).
  if (s.empty() || s.size() > 64 || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

std::string topicList(const std::vector<std::string>& topics) {
  std::string s;
  for (const auto& t : topics) s += "<topic>" + t + "</topic>";
  return s;
}

}  // namespace

const char* roleName(Role r) {
  switch (r) {
    case Role::Tracking: return "tr";
    case Role::Mapping: return "lm";
    case Role::LoopClosing: return "lc";
    case Role::Camera: return "camera";
    case Role::Viewer: return "view";
  }
  return "?";
}

Identity parseIdentity(const std::string& spec) {
  const auto colon = spec.find(':');
  Identity id{spec.substr(0, colon)};
  const std::string role = colon == std::string::npos ? spec : spec.substr(colon + 1);
  if (!validName(id.name))
    throw InputError("node name '" + id.name + "': a letter, then letters, digits and '_' (it is part of its ROS topics)");
  if (role == "tr") id.role = Role::Tracking;
  else if (role == "lm") id.role = Role::Mapping;
  else if (role == "lc") id.role = Role::LoopClosing;
  else if (role == "play" || role == "camera") id.role = Role::Camera;
  else if (role == "view") id.role = Role::Viewer;
  else throw InputError("'" + spec + "': give the node's role as NAME:tr, lm, lc, camera or view");
  return id;
}

TopicGrant topicsOf(const Identity& id) {
  std::vector<std::string> own_view, any_view{kNodes};
  for (const char* t : kVizTopics) {
    own_view.push_back("rt/hiveslam/" + id.name + "/" + t);
    any_view.push_back(std::string("rt/hiveslam/*/") + t);
  }
  auto with_view = [&](std::vector<std::string> topics) {
    topics.insert(topics.end(), own_view.begin(), own_view.end());
    return topics;
  };
  const std::string tr_kf = topicName(Topic::TrKeyframes), lm_kf = topicName(Topic::LmKeyframes);
  const std::string lm_map = topicName(Topic::LmMap), lc_map = topicName(Topic::LcMap);
  switch (id.role) {
    case Role::Tracking: return {with_view({kNodes, tr_kf, lm_kf, lm_map, lc_map}), {kNodes, lm_map, lc_map, kCamera}};
    case Role::Mapping: return {with_view({kNodes, lm_kf, lm_map, lc_map}), {kNodes, tr_kf, lm_map, lc_map}};
    case Role::LoopClosing: return {with_view({kNodes, lc_map}), {kNodes, lm_kf, lm_map}};
    case Role::Camera: return {{kCamera}, {}};
    case Role::Viewer: return {{}, any_view};
  }
  return {};
}

std::string governanceXml() {
  // Unauthenticated participants are not answered; everything a participant sends after the
  // handshake is encrypted (AES-GCM), and every topic needs a permission to write and to read.
  return fmt::format(R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      {}
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)",
                     kDomains);
}

std::string permissionsXml(const Identity& id, const std::string& not_before, const std::string& not_after) {
  const TopicGrant g = topicsOf(id);
  std::string rules;
  if (!g.publish.empty()) rules += "<publish><topics>" + topicList(g.publish) + "</topics></publish>";
  if (!g.subscribe.empty()) rules += "<subscribe><topics>" + topicList(g.subscribe) + "</topics></subscribe>";
  return fmt::format(R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="{0}">
      <subject_name>CN={0}</subject_name>
      <validity><not_before>{1}</not_before><not_after>{2}</not_after></validity>
      <allow_rule>
        {3}
        {4}
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
)",
                     id.name, not_before, not_after, kDomains, rules);
}

}  // namespace hiveslam::communication::security
