#include "viz/web/web_viewer.hpp"

#include <httplib.h>

#include <atomic>
#include <thread>

#include "common/error.hpp"
#include "common/thread_name.hpp"
#include "viz/web/view_stream.hpp"
#include "viz/web/web_assets.hpp"

namespace hiveslam::viz::web {

struct WebViewer::Impl {
  const LiveView& view;
  ViewSettings settings;
  httplib::Server server;
  std::thread thread;
  int port = 0;
  std::atomic<bool> stopping{false};
  std::atomic<uint64_t> bytes{0};
  std::atomic<int> pages{0};

  Impl(const LiveView& v, ViewSettings s) : view(v), settings(s) {}
};

WebViewer::WebViewer(const LiveView& view, const std::string& host, int port, ViewSettings settings)
    : impl_(std::make_unique<Impl>(view, settings)) {
  if (port < 0 || port > 65535) throw InputError("viewer port must be 0-65535");
  Impl& d = *impl_;
  d.server.Get(R"(/(|viewer\.js|viewer\.css|three\.min\.js|OrbitControls\.js))",
               [](const httplib::Request& req, httplib::Response& res) {
                 const WebAsset* a = findAsset(req.path);
                 if (!a) {
                   res.status = 404;
                   return;
                 }
                 res.set_content(a->body.data(), a->body.size(), std::string(a->content_type).c_str());
               });
  d.server.Get("/events", [&d](const httplib::Request&, httplib::Response& res) {
    auto stream = std::make_shared<ViewStream>(d.view, d.settings);
    res.set_header("Cache-Control", "no-cache");
    ++d.pages;
    res.set_chunked_content_provider(
        "text/event-stream",
        [&d, stream](size_t, httplib::DataSink& sink) {
          if (d.stopping) return false;
          std::string out = stream->next(std::chrono::milliseconds(250));
          // A comment line keeps the connection alive and shows a closed page within 250 ms.
          if (out.empty()) out = ":\n\n";
          d.bytes += out.size();
          return sink.write(out.data(), out.size());
        },
        [&d](bool) { --d.pages; });
  });
  d.server.set_write_timeout(5, 0);
  const int bound = port == 0 ? d.server.bind_to_any_port(host) : (d.server.bind_to_port(host, port) ? port : -1);
  if (bound < 0) throw InputError("viewer: cannot listen on " + host + ":" + std::to_string(port));
  d.port = bound;
  d.thread = std::thread([&d] {
    nameThisThread("viz-http");
    d.server.listen_after_bind();
  });
}

WebViewer::~WebViewer() {
  impl_->stopping = true;
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

int WebViewer::port() const { return impl_->port; }

uint64_t WebViewer::bytesSent() const { return impl_->bytes; }

int WebViewer::pages() const { return impl_->pages; }

}  // namespace hiveslam::viz::web
