#include "view/server.hpp"

#include <httplib.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "crowddb/error.hpp"
#include "view/viewer_assets.hpp"

namespace crowddb::view {
namespace {

template <class T>
void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // little-endian hosts only (x86-64, arm64)
  out.append(b, sizeof(T));
}

constexpr std::size_t kMaxRows = 1'000'000;  // agent rows per frames answer (about 37 MB)

const char* kNoPage =
    "<!doctype html><title>crowddb view</title><p>This crowddb was built without the viewer's "
    "page (npm was not run: see README, scripts/install-deps.sh). The API answers at "
    "<a href=\"api/run\">api/run</a>.";

}  // namespace

bool viewer_page_embedded() {
  return assets::kEmbedded;
}

std::string run_json(const RunFile& run) {
  nlohmann::json j;
  j["name"] = run.name();
  j["crowddb"] = run.crowddb();
  j["first_frame"] = run.first_frame();
  j["last_frame"] = run.last_frame();
  j["fps"] = run.fps();
  const Bounds& b = run.bounds();
  j["bounds"] = {b.xmin, b.ymin, b.xmax, b.ymax};
  j["max_agents"] = run.max_agents();
  nlohmann::json blocked = nlohmann::json::array();
  for (const auto& piece : run.blocked()) {
    nlohmann::json ring = nlohmann::json::array();
    for (const Vec2& p : piece) ring.push_back({p.x, p.y});
    blocked.push_back(std::move(ring));
  }
  j["blocked"] = std::move(blocked);
  nlohmann::json goals = nlohmann::json::array();
  for (const GoalShape& g : run.goals()) {
    nlohmann::json o{{"name", g.name}};
    if (g.ring.empty()) {
      o["x"] = g.x;
      o["y"] = g.y;
      o["radius"] = g.radius;
    } else {
      nlohmann::json ring = nlohmann::json::array();
      for (const Vec2& p : g.ring) ring.push_back({p.x, p.y});
      o["ring"] = std::move(ring);
    }
    goals.push_back(std::move(o));
  }
  j["goals"] = std::move(goals);
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string metrics_json(const RunFile& run) {
  const RunFile::Metrics m = run.metrics();
  return nlohmann::json{{"time", m.time},       {"arrived", m.arrived},   {"frozen", m.frozen},
                        {"stalled", m.stalled}, {"overlaps", m.overlaps}, {"ms", m.ms}}
      .dump();
}

std::string frames_binary(const RunFile& run, int64_t from, int64_t count) {
  if (count < 1 || count > 1000)
    throw Error(Error::Kind::usage, "count: " + std::to_string(count) + " is outside 1 to 1000");
  if (from < run.first_frame() || from > run.last_frame())
    throw Error(Error::Kind::usage, "from: frame " + std::to_string(from) + " is outside " +
                                        std::to_string(run.first_frame()) + " to " +
                                        std::to_string(run.last_frame()));
  const int64_t to = run.last_frame() - from < count - 1 ? run.last_frame() : from + count - 1;
  std::string out;
  put<uint32_t>(out, 0x46424443u);
  put<uint32_t>(out, 0);  // the number of frames, set at the end
  uint32_t frames = 0;
  std::size_t rows = 0;
  for (int64_t k = from; k <= to; ++k) {
    const std::vector<FrameAgent> a = run.frame(k);
    // At most kMaxRows agent rows per answer, never splitting a frame: memory stays bounded
    // however many agents a frame holds (the page asks again from where this one ends).
    if (frames > 0 && rows + a.size() > kMaxRows) break;
    rows += a.size();
    ++frames;
    const std::size_t start = out.size();
    put<int32_t>(out, static_cast<int32_t>(k));  // RunFile keeps frames within int32
    put<uint32_t>(out, static_cast<uint32_t>(a.size()));
    for (const FrameAgent& f : a) put<double>(out, static_cast<double>(f.id));
    for (const FrameAgent& f : a) put<float>(out, static_cast<float>(f.x));
    for (const FrameAgent& f : a) put<float>(out, static_cast<float>(f.y));
    for (const FrameAgent& f : a) put<float>(out, static_cast<float>(f.radius));
    for (const FrameAgent& f : a) put<float>(out, static_cast<float>(std::hypot(f.vx, f.vy)));
    for (const FrameAgent& f : a) put<int32_t>(out, static_cast<int32_t>(f.goal));
    for (const FrameAgent& f : a) put<uint8_t>(out, static_cast<uint8_t>(f.shade));
    while ((out.size() - start) % 8) out.push_back('\0');
  }
  std::memcpy(out.data() + 4, &frames, sizeof frames);
  return out;
}

void serve(RunFile& run, const ServeOptions& opt,
           const std::function<void(const std::string&)>& ready) {
  run.index_frames();
  const std::string run_body = run_json(run);
  httplib::Server svr;
  auto asset = [&svr](const char* path, const char* type, const unsigned char* data,
                      std::size_t size) {
    svr.Get(path, [=](const httplib::Request&, httplib::Response& res) {
      res.set_content(reinterpret_cast<const char*>(data), size, type);
    });
  };
  if (viewer_page_embedded()) {
    asset("/", "text/html; charset=utf-8", assets::kIndexHtml, assets::kIndexHtmlSize);
    asset("/index.html", "text/html; charset=utf-8", assets::kIndexHtml, assets::kIndexHtmlSize);
    asset("/app.js", "text/javascript; charset=utf-8", assets::kAppJs, assets::kAppJsSize);
    asset("/app.css", "text/css; charset=utf-8", assets::kAppCss, assets::kAppCssSize);
  } else {
    svr.Get("/", [](const httplib::Request&, httplib::Response& res) {
      res.set_content(kNoPage, "text/html; charset=utf-8");
    });
  }
  svr.Get("/api/run", [&](const httplib::Request&, httplib::Response& res) {
    res.set_content(run_body, "application/json");
  });
  svr.Get("/api/metrics", [&](const httplib::Request&, httplib::Response& res) {
    res.set_content(metrics_json(run), "application/json");
  });
  svr.Get("/api/frames", [&](const httplib::Request& req, httplib::Response& res) {
    auto number = [&](const char* key, int64_t fallback) {
      if (!req.has_param(key)) return fallback;
      const std::string v = req.get_param_value(key);
      char* end = nullptr;
      errno = 0;
      const long long n = std::strtoll(v.c_str(), &end, 10);
      if (v.empty() || *end || errno == ERANGE)
        throw Error(Error::Kind::usage, std::string(key) + ": '" + v + "' is not an integer");
      return static_cast<int64_t>(n);
    };
    try {
      res.set_content(frames_binary(run, number("from", run.first_frame()), number("count", 1)),
                      "application/octet-stream");
    } catch (const Error& e) {
      res.status = 400;
      res.set_content(e.what(), "text/plain");
    }
  });
  svr.set_exception_handler(
      [](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
        res.status = 500;
        try {
          std::rethrow_exception(ep);
        } catch (const std::exception& e) {
          res.set_content(e.what(), "text/plain");
        } catch (...) {
          res.set_content("internal error", "text/plain");
        }
      });
  // SO_REUSEADDR only: the library's default adds SO_REUSEPORT, with which a second server on
  // the same port would share (and mix) the connections instead of failing.
  svr.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, reinterpret_cast<const char*>(&yes), sizeof yes);
  });
  // On loopback, answer only requests addressed to this machine by name or address: a web page
  // elsewhere that rebinds its DNS name to 127.0.0.1 cannot read the run.
  const bool loopback = opt.host == "127.0.0.1" || opt.host == "localhost" || opt.host == "::1";
  svr.set_pre_routing_handler([loopback](const httplib::Request& req, httplib::Response& res) {
    if (!loopback) return httplib::Server::HandlerResponse::Unhandled;
    std::string host = req.get_header_value("Host");
    if (const auto colon = host.rfind(':'); colon != std::string::npos && host.back() != ']')
      host.resize(colon);
    if (host == "127.0.0.1" || host == "localhost" || host == "[::1]")
      return httplib::Server::HandlerResponse::Unhandled;
    res.status = 403;
    res.set_content("crowddb view answers requests to 127.0.0.1 or localhost only", "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  });
  int port = opt.port;
  if (port == 0) {
    port = svr.bind_to_any_port(opt.host);
    if (port < 0) throw Error(Error::Kind::io, opt.host + ": cannot listen on any port");
  } else if (!svr.bind_to_port(opt.host, port)) {
    throw Error(Error::Kind::io, opt.host + ":" + std::to_string(port) +
                                     ": cannot listen (the port is in use, or the address is not "
                                     "this machine's): choose another with --port, or --port 0");
  }
  ready("http://" + opt.host + ":" + std::to_string(port) + "/");
  svr.listen_after_bind();
}

}  // namespace crowddb::view
