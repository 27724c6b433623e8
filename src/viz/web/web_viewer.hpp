#pragma once
// The web viewer: one page at http://HOST:PORT/ (a 3D view of the maps, the trajectory and the
// camera; the current image; a panel per node) with updates pushed as server-sent events from
// /events. Its own HTTP threads read the LiveView; nothing it does waits on tracking.
#include <memory>
#include <string>

#include "viz/live_view.hpp"
#include "viz/view_settings.hpp"

namespace hiveslam::viz::web {

class WebViewer {
 public:
  // Listens on `host`:`port` (port 0: any free port, see port()); throws InputError when it
  // cannot bind.
  WebViewer(const LiveView& view, const std::string& host, int port, ViewSettings settings);
  ~WebViewer();
  WebViewer(const WebViewer&) = delete;
  WebViewer& operator=(const WebViewer&) = delete;
  int port() const;
  // Bytes of events sent to all pages so far.
  uint64_t bytesSent() const;
  // Pages reading the event stream now.
  int pages() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hiveslam::viz::web
