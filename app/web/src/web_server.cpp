#include "craneassist/web/web_server.hpp"

#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <deque>
#include <future>
#include <mutex>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "craneassist/input/gamepad.hpp"
#include "craneassist/input/joystick_mapping.hpp"
#include "craneassist/input/latest_pad.hpp"
#include "craneassist/input/triple_buffer.hpp"
#include "craneassist/net/listener.hpp"
#include "pad_message.hpp"
#include "scene.hpp"

// The page, bundled by the build (app/web/page, esbuild) and linked in (page_assets.S).
extern "C" {
extern const char craneassist_web_index_html[];
extern const char craneassist_web_index_html_end[];
extern const char craneassist_web_app_js[];
extern const char craneassist_web_app_js_end[];
}

namespace craneassist::web {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

std::string_view asset(const char* begin, const char* end) {
  return {begin, static_cast<std::size_t>(end - begin)};
}

std::string random_token() {
  auto token = craneassist::net::random_hex(16);
  if (!token) throw std::runtime_error("web: cannot read /dev/urandom for the session token");
  return *token;
}

// The value of `name` in the query of a request target ("/ws?token=abc&x=1"), or "".
std::string query_value(std::string_view target, std::string_view name) {
  const auto q = target.find('?');
  if (q == std::string_view::npos) return {};
  std::string_view rest = target.substr(q + 1);
  while (!rest.empty()) {
    const auto amp = rest.find('&');
    const std::string_view pair = rest.substr(0, amp);
    const auto eq = pair.find('=');
    if (eq != std::string_view::npos && pair.substr(0, eq) == name) {
      return std::string(pair.substr(eq + 1));
    }
    if (amp == std::string_view::npos) break;
    rest = rest.substr(amp + 1);
  }
  return {};
}

std::string_view path_of(std::string_view target) {
  return target.substr(0, target.find('?'));
}

// Compares without stopping at the first difference (the token is a secret).
bool same_secret(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  }
  return diff == 0;
}

}  // namespace

class WsSession;

struct WebServer::Impl {
  Impl(const WebOptions& o, const config::CraneConfig& crane)
      : options(o),
        crane_text(crane_json(crane, o.frame_rate_hz)),
        scene(crane.model, o.base),
        token(o.token.empty() ? random_token() : o.token),
        acceptor(ioc),
        timer(ioc) {}

  // The loop's side.
  class Observer : public control::CycleObserver {
   public:
    explicit Observer(Impl& impl) : impl_(impl) {}
    void on_cycle(const control::CycleRecord& cycle) noexcept override { impl_.publish(cycle.row); }

   private:
    Impl& impl_;
  };

  // Hands a row to the I/O thread without waiting; the page samples the newest at its own rate,
  // and the last row of a run (its end) is always sent.
  void publish(const control::LogRow& r) noexcept {
    Published& p = rows.back();
    p.row = r;
    p.seq = ++published_seq;
    rows.publish();
  }
  void start();
  void tick();
  void broadcast(const std::shared_ptr<const std::string>& message);
  void on_pad(WsSession& from, std::string_view text);
  void on_closed(WsSession& session);
  void publish_disconnected();
  void shutdown();

  WebOptions options;
  std::string crane_text;
  SceneBuilder scene;
  std::string token;
  net::io_context ioc{1};
  tcp::acceptor acceptor;
  net::steady_timer timer;
  std::thread thread;
  std::promise<void> stopped;

  // Loop -> I/O thread.
  struct Published {
    control::LogRow row;
    std::uint64_t seq = 0;  // how many rows were published up to this one
  };
  input::TripleBuffer<Published> rows;  // from the loop (or the DDS watch) to the I/O thread
  std::uint64_t published_seq = 0;      // the publishing thread's
  // I/O thread only.
  std::string frame_text;
  std::vector<std::weak_ptr<WsSession>> sessions;
  WsSession* holder = nullptr;

  // I/O thread -> loop: the page's stick state (the loop takes it with try_lock, never waits).
  // `connected`: a page holds the command; `has_state`: a page has held it.
  input::LatestPad pad;
  input::GamepadButton deadman_button = input::GamepadButton::kRightShoulder;
  std::atomic<bool> pad_source_made{false};

  Observer observer{*this};

  // Counted on the I/O thread, read by counters() from any thread.
  mutable std::mutex counters_mutex;
  WebCounters counts;
  void count(std::uint64_t WebCounters::*counter) {
    std::lock_guard<std::mutex> lock(counters_mutex);
    ++(counts.*counter);
  }
};

// One page's WebSocket: frames out (a short queue; a page that falls behind misses frames, it
// never holds the server up), stick states in.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket&& socket, WebServer::Impl& impl, bool may_command)
      : ws_(std::move(socket)), impl_(impl), may_command_(may_command) {}

  void run(http::request<http::string_body> req) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(4096);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->impl_.count(&WebCounters::pages_connected);
      self->impl_.sessions.push_back(self);
      self->send(
          std::make_shared<const std::string>(std::string("{\"type\":\"hello\",\"command\":\"") +
                                              (self->may_command_ ? "available" : "view") + "\"}"));
      self->read();
    });
  }

  // Queues a message; false when the page is behind (the message is dropped).
  bool send(const std::shared_ptr<const std::string>& message) {
    if (closed_ || queue_.size() >= 2) return false;
    queue_.push_back(message);
    if (queue_.size() == 1) write();
    return true;
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    ws_.async_close(websocket::close_code::going_away,
                    [self = shared_from_this()](beast::error_code) {});
  }

  bool may_command() const { return may_command_; }
  bool told_refused = false;

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        self->closed_ = true;
        self->impl_.on_closed(*self);
        return;
      }
      const auto data = self->buffer_.data();
      self->impl_.on_pad(*self,
                         std::string_view(static_cast<const char*>(data.data()), data.size()));
      self->buffer_.consume(self->buffer_.size());
      self->read();
    });
  }

  void write() {
    ws_.text(true);
    ws_.async_write(net::buffer(*queue_.front()),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      if (ec) {
                        self->queue_.clear();
                        return;
                      }
                      self->queue_.pop_front();
                      if (!self->queue_.empty()) self->write();
                    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  WebServer::Impl& impl_;
  bool may_command_;
  bool closed_ = false;
};

namespace {

// One HTTP connection: the page's files, /crane.json, and the upgrade to /ws.
class HttpSession : public craneassist::net::HttpConnection<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, WebServer::Impl& impl)
      : HttpConnection(std::move(socket)), impl_(impl) {}

  void handle(http::request<http::string_body> req) {
    impl_.count(&WebCounters::http_requests);
    const std::string_view target(req.target().data(), req.target().size());
    if (websocket::is_upgrade(req) && path_of(target) == "/ws") {
      beast::error_code ec;
      const auto peer = stream_.socket().remote_endpoint(ec);
      const bool local = !ec && peer.address().is_loopback();
      const bool may_command = impl_.options.commands &&
                               same_secret(query_value(target, "token"), impl_.token) &&
                               (local || impl_.options.remote_commands);
      stream_.expires_never();
      std::make_shared<WsSession>(stream_.release_socket(), impl_, may_command)
          ->run(std::move(req));
      return;
    }
    auto res = std::make_shared<http::response<http::string_body>>();
    res->version(req.version());
    res->keep_alive(req.keep_alive());
    res->set(http::field::server, "craneassist");
    res->set(http::field::cache_control, "no-store");
    res->set("X-Content-Type-Options", "nosniff");
    const std::string_view path = path_of(target);
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      res->result(http::status::method_not_allowed);
      res->set(http::field::content_type, "text/plain");
      res->body() = "only GET\n";
    } else if (path == "/" || path == "/index.html") {
      res->set(http::field::content_type, "text/html; charset=utf-8");
      res->body() = asset(craneassist_web_index_html, craneassist_web_index_html_end);
    } else if (path == "/app.js") {
      res->set(http::field::content_type, "text/javascript; charset=utf-8");
      res->body() = asset(craneassist_web_app_js, craneassist_web_app_js_end);
    } else if (path == "/crane.json") {
      res->set(http::field::content_type, "application/json");
      res->body() = impl_.crane_text;
    } else {
      res->result(http::status::not_found);
      res->set(http::field::content_type, "text/plain");
      res->body() = "not found\n";
    }
    res->prepare_payload();
    if (req.method() == http::verb::head) res->body().clear();
    http::async_write(stream_, *res,
                      [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
                        if (ec || !res->keep_alive()) {
                          self->shutdown();
                          return;
                        }
                        self->read();
                      });
  }

 private:
  WebServer::Impl& impl_;
};

}  // namespace

void WebServer::Impl::start() {
  craneassist::net::listen(acceptor, options.address, options.port, "web");
  craneassist::net::accept_into(acceptor, [this](tcp::socket socket) {
    std::make_shared<HttpSession>(std::move(socket), *this)->read();
  });
  tick();
  thread = craneassist::net::run_io_thread(ioc, stopped, "web");
}

void WebServer::Impl::tick() {
  // No page: no drawing to compute (the newest row waits for the first page).
  if (!sessions.empty() && rows.update()) {
    scene.frame_json(rows.front().row, rows.front().seq, frame_text);
    broadcast(std::make_shared<const std::string>(frame_text));
  }
  const double rate = options.frame_rate_hz > 0.0 ? options.frame_rate_hz : 30.0;
  timer.expires_after(std::chrono::microseconds(static_cast<long>(1e6 / rate)));
  timer.async_wait([this](beast::error_code ec) {
    if (!ec) tick();
  });
}

void WebServer::Impl::broadcast(const std::shared_ptr<const std::string>& message) {
  std::size_t live = 0;
  for (auto& weak : sessions) {
    if (auto s = weak.lock()) {
      if (s->send(message)) {
        count(&WebCounters::frames_sent);
      } else {
        count(&WebCounters::frames_dropped);
      }
      sessions[live++] = weak;
    }
  }
  sessions.resize(live);
}

void WebServer::Impl::on_pad(WsSession& from, std::string_view text) {
  auto reply = [&from](const char* state, const char* why) {
    from.send(std::make_shared<const std::string>(
        std::string("{\"type\":\"command\",\"state\":\"") + state + "\",\"why\":\"" + why + "\"}"));
  };
  if (!pad_source_made.load() || !from.may_command() || (holder != nullptr && holder != &from)) {
    count(&WebCounters::pad_refused);
    if (!from.told_refused) {
      from.told_refused = true;
      reply("refused", !pad_source_made.load() ? "this run does not take commands from the page"
                       : !from.may_command()
                           ? "commands need the session token from the local machine"
                           : "another page holds the command");
    }
    return;
  }
  PadMessage m;
  if (!parse_pad_message(text, m)) {
    // Not published: the last good state goes stale and the crane stops.
    count(&WebCounters::pad_malformed);
    return;
  }
  input::PadSnapshot s;
  for (std::size_t i = 0; i < input::kGamepadAxisCount && i < m.axes.size(); ++i) {
    s.pad.axes[i] = m.axes[i];
  }
  s.pad.set_button(deadman_button, m.deadman);
  s.stamp_s = input::steady_now_s();
  s.connected = true;
  s.has_state = true;
  if (holder == nullptr) {
    holder = &from;
    count(&WebCounters::command_holders);
    reply("yours", "");
  }
  count(&WebCounters::pad_messages);
  pad.publish(s);
}

void WebServer::Impl::on_closed(WsSession& session) {
  if (holder == &session) {
    holder = nullptr;
    publish_disconnected();
  }
}

void WebServer::Impl::publish_disconnected() {
  input::PadSnapshot s;
  s.connected = false;
  s.has_state = true;
  s.stamp_s = input::steady_now_s();
  pad.publish(s);
}

void WebServer::Impl::shutdown() {
  beast::error_code ignored;
  acceptor.close(ignored);
  timer.cancel();
  for (auto& weak : sessions) {
    if (auto s = weak.lock()) s->close();
  }
  sessions.clear();
}

// The page's virtual joystick, mapped like a physical pad.
class PadSource : public input::CommandSource {
 public:
  PadSource(WebServer::Impl& impl, const input::JoystickMapping& mapping)
      : impl_(impl), mapper_(mapping) {}

  void begin_cycle(double, const Eigen::Vector3d& tip_m) noexcept override { tip_ = tip_m; }
  input::SourceState poll(input::OperatorCommand& out) noexcept override {
    impl_.pad.try_take(taken_);
    if (!taken_.has_state) return input::SourceState::kNoData;
    if (!taken_.connected) return input::SourceState::kDisconnected;
    out.v_m_s = mapper_.map(taken_.pad, tip_);
    out.deadman = mapper_.deadman(taken_.pad);
    out.drive = mapper_.drive(taken_.pad);
    out.stamp_s = taken_.stamp_s;
    return input::SourceState::kOk;
  }
  const char* name() const noexcept override { return "web"; }

 private:
  WebServer::Impl& impl_;
  input::JoystickMapper mapper_;
  input::PadSnapshot taken_;
  Eigen::Vector3d tip_ = Eigen::Vector3d::UnitX();
};

WebServer::WebServer(const WebOptions& options, const config::CraneConfig& crane)
    : impl_(std::make_unique<Impl>(options, crane)) {
  impl_->start();
}

WebServer::~WebServer() {
  craneassist::net::stop_io_thread(
      impl_->ioc, impl_->thread, impl_->stopped, [impl = impl_.get()] { impl->shutdown(); }, 0.5);
}

unsigned short WebServer::port() const {
  beast::error_code ec;
  return impl_->acceptor.local_endpoint(ec).port();
}

std::string WebServer::url() const {
  return "http://" + craneassist::net::client_host_port(impl_->options.address, port()) +
         "/?token=" + impl_->token;
}

control::CycleObserver& WebServer::observer() {
  return impl_->observer;
}

void WebServer::publish(const control::LogRow& row) noexcept {
  impl_->publish(row);
}

std::unique_ptr<input::CommandSource> WebServer::make_pad_source(
    const input::JoystickMapping& mapping) {
  if (impl_->pad_source_made.exchange(true)) {
    throw std::logic_error("web: one pad source per server");
  }
  impl_->deadman_button = mapping.deadman;
  return std::make_unique<PadSource>(*impl_, mapping);
}

WebCounters WebServer::counters() const {
  std::lock_guard<std::mutex> lock(impl_->counters_mutex);
  return impl_->counts;
}

std::string WebServer::report() const {
  const WebCounters c = counters();
  using std::to_string;
  return "  web: " + to_string(c.pages_connected) + " pages, " + to_string(c.frames_sent) +
         " frames sent (" + to_string(c.frames_dropped) +
         " dropped: a page behind), stick states " + to_string(c.pad_messages) + " accepted, " +
         to_string(c.pad_refused) + " refused, " + to_string(c.pad_malformed) + " malformed; " +
         to_string(c.command_holders) + " pages took the command";
}

}  // namespace craneassist::web
