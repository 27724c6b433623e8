#pragma once
// Who may do what on a secure domain: the governance document (every participant
// authenticated, discovery, liveliness, RTPS messages and payloads encrypted, every topic under
// access control) and each identity's permissions, the topics it may write and read.
//
// Tasks move between nodes at run time, so a node's grant covers every plan its own task can
// take part in (distribution/policy.cpp): a tracking node maps and closes loops while it is
// alone and hands the maps over on LM's and LC's topics when they come, so it writes all four
// packet topics; a mapping node never writes TR's keyframes; a loop-closing node writes only
// LC's maps. Camera images go only from a camera identity to tracking nodes, and a viewer
// writes nothing at all.
#include <string>
#include <vector>

namespace hiveslam::communication::security {

enum class Role { Tracking, Mapping, LoopClosing, Camera, Viewer };

struct Identity {
  std::string name;  // the certificate's common name and the node's name
  Role role = Role::Viewer;
};

// "tr", "lm", "lc", "play" (Camera) and "view" name their role; "NAME:ROLE" gives one (ROLE
// one of tr, lm, lc, camera, view; NAME letters, digits, '-' and '_'). Throws InputError.
Identity parseIdentity(const std::string& spec);
const char* roleName(Role r);

struct TopicGrant {
  std::vector<std::string> publish, subscribe;  // DDS topic names; '*' matches any run of characters
};
TopicGrant topicsOf(const Identity& id);

std::string governanceXml();
// not_before/not_after: "YYYY-MM-DDTHH:MM:SS" (UTC).
std::string permissionsXml(const Identity& id, const std::string& not_before, const std::string& not_after);

}  // namespace hiveslam::communication::security
