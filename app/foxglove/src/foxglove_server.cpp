#include "craneassist/foxglove/foxglove_server.hpp"

#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <deque>
#include <future>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <vector>

#include "craneassist/foxglove/channels.hpp"
#include "craneassist/foxglove/cycle_hand_over.hpp"
#include "craneassist/net/listener.hpp"

namespace craneassist::foxglove {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using json = nlohmann::json;

namespace {

constexpr const char* kSubprotocols[] = {"foxglove.sdk.v1", "foxglove.websocket.v1"};
constexpr std::uint8_t kMessageData = 0x01;
constexpr std::uint8_t kTime = 0x02;

// The first subprotocol of ours that the client's Sec-WebSocket-Protocol list offers, or "".
std::string pick_subprotocol(std::string_view offered) {
  for (const char* ours : kSubprotocols) {
    std::string_view rest = offered;
    while (!rest.empty()) {
      const auto comma = rest.find(',');
      std::string_view item = rest.substr(0, comma);
      while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
      while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
      if (item == ours) return ours;
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
  }
  return {};
}

template <class T>
void put_le(std::vector<std::uint8_t>& out, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i)
    out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

struct Outgoing {
  std::vector<std::uint8_t> bytes;
  bool text = false;
};
using OutgoingPtr = std::shared_ptr<const Outgoing>;

// A Message Data frame: opcode, subscription id, time (ns), the message.
OutgoingPtr message_data(std::uint32_t subscription, std::uint64_t t_ns,
                         const std::vector<std::uint8_t>& message) {
  auto m = std::make_shared<Outgoing>();
  m->bytes.reserve(13 + message.size());
  m->bytes.push_back(kMessageData);
  put_le(m->bytes, subscription);
  put_le(m->bytes, t_ns);
  m->bytes.insert(m->bytes.end(), message.begin(), message.end());
  return m;
}

OutgoingPtr text_message(const std::string& s) {
  auto m = std::make_shared<Outgoing>();
  m->bytes.assign(s.begin(), s.end());
  m->text = true;
  return m;
}

}  // namespace

bool parse_listen_address(const std::string& text, ServerOptions& options, std::string& why) {
  std::string host = options.address, port = text;
  if (const auto colon = text.rfind(':'); colon != std::string::npos) {
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
      host = host.substr(1, host.size() - 2);
    }
    if (host.empty()) {
      why = "no host before ':' in '" + text + "' (give PORT or HOST:PORT)";
      return false;
    }
  }
  if (port.empty() || port.size() > 5 ||
      port.find_first_not_of("0123456789") != std::string::npos || std::stoul(port) > 65535) {
    why = "'" + text + "' is not a port (0..65535) or HOST:PORT";
    return false;
  }
  beast::error_code ec;
  net::ip::make_address(host, ec);
  if (ec) {
    why = "'" + host + "' is not an IP address";
    return false;
  }
  options.address = host;
  options.port = static_cast<unsigned short>(std::stoul(port));
  return true;
}

class FoxgloveSession;

struct FoxgloveServer::Impl {
  Impl(const ServerOptions& o, const dynamics::CraneModel& model)
      : options(o),
        channels(model, o.base),
        cycles(o.ring_rows),
        // Not a secret (the web view's token is): all zeros if /dev/urandom cannot be read.
        session_id(craneassist::net::random_hex(8).value_or(std::string(16, '0'))),
        acceptor(ioc),
        timer(ioc) {
    // serverInfo and advertise: the same for every client.
    json info = {{"op", "serverInfo"},
                 {"name", "craneassist"},
                 {"capabilities", o.sim_time ? json::array({"time"}) : json::array()},
                 {"supportedEncodings", json::array()},
                 {"metadata", {{"crane", model.name}}},
                 {"sessionId", session_id}};
    server_info = text_message(info.dump());
    json list = json::array();
    for (std::size_t k = 0; k < channels.size(); ++k) {
      const Channel& c = channels.channels()[k];
      list.push_back({{"id", k + 1},
                      {"topic", c.topic},
                      {"encoding", c.message_encoding},
                      {"schemaName", c.schema_name},
                      {"schema", c.schema},
                      {"schemaEncoding", c.schema_encoding}});
    }
    advertise = text_message(json{{"op", "advertise"}, {"channels", list}}.dump());
    subscribers.assign(channels.size(), 0);
  }

  class Observer : public control::CycleObserver {
   public:
    explicit Observer(CycleHandOver& cycles) : cycles_(cycles) {}
    void on_cycle(const control::CycleRecord& cycle) noexcept override { cycles_.push(cycle); }

   private:
    CycleHandOver& cycles_;
  };

  void start();
  void tick();
  void drain();
  void on_text(FoxgloveSession& s, std::string_view text);
  void on_binary(FoxgloveSession& s);
  void status(FoxgloveSession& s, int level, const std::string& message);
  void send_latched(FoxgloveSession& s, std::uint32_t id, std::uint64_t t_ns);
  void shutdown();

  ServerOptions options;
  ChannelSet channels;
  CycleHandOver cycles;  // from the loop
  std::string session_id;
  OutgoingPtr server_info, advertise;
  net::io_context ioc{1};
  tcp::acceptor acceptor;
  net::steady_timer timer;
  std::thread thread;
  std::promise<void> stopped;
  // I/O thread only.
  std::vector<std::weak_ptr<FoxgloveSession>> sessions;
  std::vector<int> subscribers;  // per channel, over all sessions
  // Subscriptions to the latched description made before the first cycle: it is sent with the
  // first cycle, so a viewer never has the crane's URDF without its pose (the URDF alone draws
  // every joint at zero).
  std::vector<std::pair<std::weak_ptr<FoxgloveSession>, std::uint32_t>> latched_waiting;
  std::optional<std::uint64_t> last_cycle_ns;  // the message time of the last cycle drained
  std::vector<std::uint8_t> encoded;
  Observer observer{cycles};
  // Counters (any thread reads them).
  std::atomic<std::uint64_t> clients_connected{0}, subscriptions_made{0}, messages_sent{0},
      messages_dropped{0}, client_malformed{0}, client_unsupported{0}, refused{0};
};

// One client: message frames out (a queue bounded in bytes; a client behind loses frames),
// subscribe and unsubscribe in.
class FoxgloveSession : public std::enable_shared_from_this<FoxgloveSession> {
 public:
  FoxgloveSession(tcp::socket&& socket, FoxgloveServer::Impl& impl)
      : ws_(std::move(socket)), impl_(impl) {}

  void run(http::request<http::string_body> req, std::string subprotocol) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator([subprotocol](websocket::response_type& res) {
      res.set(http::field::sec_websocket_protocol, subprotocol);
      res.set(http::field::server, "craneassist");
    }));
    ws_.read_message_max(64 << 10);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->impl_.clients_connected.fetch_add(1);
      self->impl_.sessions.push_back(self);
      self->send(self->impl_.server_info, true);
      self->send(self->impl_.advertise, true);
      self->read();
    });
  }

  // Queues a message; false (dropped) when the client is behind. `always`: the handshake's
  // messages and statuses, queued whatever the backlog.
  bool send(const OutgoingPtr& m, bool always = false) {
    if (closed_) return false;
    if (!always && queued_bytes_ + m->bytes.size() > impl_.options.max_queue_bytes) return false;
    queued_bytes_ += m->bytes.size();
    queue_.push_back(m);
    if (queue_.size() == 1) write();
    return true;
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    release();
    ws_.async_close(websocket::close_code::going_away,
                    [self = shared_from_this()](beast::error_code) {});
  }

  // subscription id -> channel index
  std::map<std::uint32_t, std::size_t> subscriptions;
  bool closed() const { return closed_; }

  // The channels this session no longer counts as subscribed (on close).
  void release() {
    for (const auto& [id, k] : subscriptions) --impl_.subscribers[k];
    subscriptions.clear();
  }

 private:
  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        if (!self->closed_) {
          self->closed_ = true;
          self->release();
        }
        return;
      }
      const auto data = self->buffer_.data();
      if (self->ws_.got_text()) {
        self->impl_.on_text(*self,
                            std::string_view(static_cast<const char*>(data.data()), data.size()));
      } else {
        self->impl_.on_binary(*self);
      }
      self->buffer_.consume(self->buffer_.size());
      self->read();
    });
  }

  void write() {
    const Outgoing& m = *queue_.front();
    ws_.text(m.text);
    ws_.binary(!m.text);
    ws_.async_write(net::buffer(m.bytes),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      if (ec) {
                        self->queue_.clear();
                        self->queued_bytes_ = 0;
                        return;
                      }
                      self->queued_bytes_ -= self->queue_.front()->bytes.size();
                      self->queue_.pop_front();
                      if (!self->queue_.empty()) self->write();
                    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buffer_;
  std::deque<OutgoingPtr> queue_;
  std::size_t queued_bytes_ = 0;
  FoxgloveServer::Impl& impl_;
  bool closed_ = false;
};

namespace {

// One HTTP connection: the WebSocket upgrade with a Foxglove subprotocol, or a plain answer.
class HttpSession : public craneassist::net::HttpConnection<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, FoxgloveServer::Impl& impl)
      : HttpConnection(std::move(socket)), impl_(impl) {}

  void handle(http::request<http::string_body> req) {
    std::string subprotocol;
    if (websocket::is_upgrade(req)) {
      const auto offered = req[http::field::sec_websocket_protocol];
      subprotocol = pick_subprotocol(std::string_view(offered.data(), offered.size()));
      if (!subprotocol.empty()) {
        stream_.expires_never();
        std::make_shared<FoxgloveSession>(stream_.release_socket(), impl_)
            ->run(std::move(req), subprotocol);
        return;
      }
    }
    impl_.refused.fetch_add(1);
    auto res = std::make_shared<http::response<http::string_body>>(http::status::bad_request,
                                                                   req.version());
    res->set(http::field::server, "craneassist");
    res->set(http::field::content_type, "text/plain");
    res->body() =
        "craneassist: a Foxglove WebSocket server (subprotocol foxglove.sdk.v1 or "
        "foxglove.websocket.v1): open it in Foxglove, Open connection, Foxglove WebSocket "
        "(docs/foxglove.md)\n";
    res->keep_alive(false);
    res->prepare_payload();
    http::async_write(
        stream_, *res,
        [self = shared_from_this(), res](beast::error_code, std::size_t) { self->shutdown(); });
  }

 private:
  FoxgloveServer::Impl& impl_;
};

}  // namespace

void FoxgloveServer::Impl::start() {
  craneassist::net::listen(acceptor, options.address, options.port, "foxglove");
  craneassist::net::accept_into(acceptor, [this](tcp::socket socket) {
    std::make_shared<HttpSession>(std::move(socket), *this)->read();
  });
  tick();
  thread = craneassist::net::run_io_thread(ioc, stopped, "foxglove");
}

void FoxgloveServer::Impl::tick() {
  drain();
  timer.expires_after(std::chrono::milliseconds(2));
  timer.async_wait([this](beast::error_code ec) {
    if (!ec) tick();
  });
}

void FoxgloveServer::Impl::drain() {
  // Drop the sessions that have closed.
  std::size_t live = 0;
  for (auto& weak : sessions) {
    auto s = weak.lock();
    if (s && !s->closed()) sessions[live++] = weak;
  }
  sessions.resize(live);
  while (const CycleHandOver::Slot* slot = cycles.front()) {
    const std::uint64_t t_ns = cycles.time_ns(slot->t_s);
    last_cycle_ns = t_ns;
    for (const auto& [weak, id] : latched_waiting) {
      if (auto s = weak.lock()) send_latched(*s, id, t_ns);
    }
    latched_waiting.clear();
    if (!sessions.empty()) {
      if (options.sim_time) {
        auto m = std::make_shared<Outgoing>();
        m->bytes.push_back(kTime);
        put_le(m->bytes, t_ns);
        for (auto& weak : sessions) {
          if (auto s = weak.lock()) s->send(m);
        }
      }
      for (std::size_t k = 0; k < channels.size(); ++k) {
        if (subscribers[k] == 0 || channels.channels()[k].latched) continue;
        channels.encode(k, slot->row, static_cast<std::int64_t>(t_ns), encoded);
        for (auto& weak : sessions) {
          auto s = weak.lock();
          if (!s) continue;
          for (const auto& [id, channel] : s->subscriptions) {
            if (channel != k) continue;
            if (s->send(message_data(id, t_ns, encoded))) {
              messages_sent.fetch_add(1, std::memory_order_relaxed);
            } else {
              messages_dropped.fetch_add(1, std::memory_order_relaxed);
            }
          }
        }
      }
    }
    cycles.pop();
  }
}

void FoxgloveServer::Impl::send_latched(FoxgloveSession& s, std::uint32_t id, std::uint64_t t_ns) {
  const auto it = s.subscriptions.find(id);
  if (it == s.subscriptions.end() || !channels.channels()[it->second].latched) return;  // gone
  const std::size_t k = it->second;
  channels.encode(k, control::LogRow{}, static_cast<std::int64_t>(t_ns), encoded);
  s.send(message_data(id, t_ns, encoded), true);
}

void FoxgloveServer::Impl::status(FoxgloveSession& s, int level, const std::string& message) {
  s.send(text_message(json{{"op", "status"}, {"level", level}, {"message", message}}.dump()), true);
}

void FoxgloveServer::Impl::on_binary(FoxgloveSession& s) {
  client_unsupported.fetch_add(1);
  status(s, 2, "craneassist takes no client messages (no clientPublish): dropped");
}

ClientRequest parse_client_request(std::string_view text) {
  ClientRequest r;
  const json m = json::parse(text, nullptr, false);
  if (m.is_discarded() || !m.is_object() || !m.contains("op") || !m["op"].is_string()) {
    r.why = "not a JSON object with an \"op\"";
    return r;
  }
  r.op = m["op"].get<std::string>();
  const auto valid_id = [](const json& v) {
    return v.is_number_unsigned() && v.get<std::uint64_t>() <= 0xFFFFFFFFULL;
  };
  if (r.op == "subscribe") {
    if (!m.contains("subscriptions") || !m["subscriptions"].is_array()) {
      r.why = "subscribe: no \"subscriptions\" array";
      return r;
    }
    r.kind = ClientRequest::Kind::kSubscribe;
    for (const json& sub : m["subscriptions"]) {
      if (!sub.is_object() || !sub.contains("id") || !sub.contains("channelId") ||
          !valid_id(sub["id"]) || !valid_id(sub["channelId"])) {
        ++r.bad_items;
        r.why = "subscribe: each subscription needs an \"id\" and a \"channelId\"";
        continue;
      }
      r.subscribe.emplace_back(sub["id"].get<std::uint32_t>(),
                               sub["channelId"].get<std::uint32_t>());
    }
    return r;
  }
  if (r.op == "unsubscribe") {
    if (!m.contains("subscriptionIds") || !m["subscriptionIds"].is_array()) {
      r.why = "unsubscribe: no \"subscriptionIds\" array";
      return r;
    }
    r.kind = ClientRequest::Kind::kUnsubscribe;
    for (const json& id : m["subscriptionIds"]) {
      if (!valid_id(id)) {
        ++r.bad_items;
        r.why = "unsubscribe: a subscription id is not a 32-bit unsigned integer";
        continue;
      }
      r.unsubscribe.push_back(id.get<std::uint32_t>());
    }
    return r;
  }
  r.kind = ClientRequest::Kind::kUnsupported;
  r.why = "craneassist does not offer '" + r.op + "' (no command input here)";
  return r;
}

void FoxgloveServer::Impl::on_text(FoxgloveSession& s, std::string_view text) {
  const ClientRequest r = parse_client_request(text);
  switch (r.kind) {
    case ClientRequest::Kind::kMalformed:
      client_malformed.fetch_add(1);
      status(s, 2, r.why + ": dropped");
      return;
    case ClientRequest::Kind::kUnsupported:
      client_unsupported.fetch_add(1);
      status(s, 2, r.why + ": dropped");
      return;
    case ClientRequest::Kind::kSubscribe:
    case ClientRequest::Kind::kUnsubscribe:
      break;
  }
  if (r.bad_items > 0) {
    client_malformed.fetch_add(static_cast<std::uint64_t>(r.bad_items));
    status(s, 2, r.why);
  }
  for (const std::uint32_t id : r.unsubscribe) {
    const auto it = s.subscriptions.find(id);
    if (it == s.subscriptions.end()) continue;
    --subscribers[it->second];
    s.subscriptions.erase(it);
  }
  for (const auto& [id, channel] : r.subscribe) {
    if (channel == 0 || channel > channels.size()) {
      client_malformed.fetch_add(1);
      status(s, 1, "subscribe: no channel " + std::to_string(channel));
      continue;
    }
    if (s.subscriptions.count(id) != 0) {
      client_malformed.fetch_add(1);
      status(s, 1, "subscribe: subscription id " + std::to_string(id) + " is taken");
      continue;
    }
    const std::size_t k = channel - 1;
    s.subscriptions[id] = k;
    ++subscribers[k];
    subscriptions_made.fetch_add(1);
    if (channels.channels()[k].latched) {
      // The latched description: now, to this subscription, or with the first cycle.
      if (last_cycle_ns) {
        send_latched(s, id, *last_cycle_ns);
      } else {
        latched_waiting.emplace_back(s.shared_from_this(), id);
      }
    }
  }
}

void FoxgloveServer::Impl::shutdown() {
  drain();
  beast::error_code ignored;
  acceptor.close(ignored);
  timer.cancel();
  for (auto& weak : sessions) {
    if (auto s = weak.lock()) s->close();
  }
  sessions.clear();
}

FoxgloveServer::FoxgloveServer(const ServerOptions& options, const dynamics::CraneModel& model)
    : impl_(std::make_unique<Impl>(options, model)) {
  impl_->start();
}

FoxgloveServer::~FoxgloveServer() {
  stop();
}

void FoxgloveServer::stop(double drain_s) {
  craneassist::net::stop_io_thread(
      impl_->ioc, impl_->thread, impl_->stopped, [impl = impl_.get()] { impl->shutdown(); },
      drain_s);
}

bool FoxgloveServer::wait_for_subscriber(double timeout_s) const {
  using clock = std::chrono::steady_clock;
  const auto until = clock::now() + std::chrono::duration<double>(timeout_s);
  while (impl_->subscriptions_made.load() == 0) {
    if (clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // A client subscribes channel by channel (a viewer: a message per panel's topic, clients
  // connecting together each their own): the run starts once the subscriptions have settled,
  // kSubscriptionsSettle after the last one (within the timeout), so that its first cycle reaches
  // every channel asked for, on a busy machine too.
  constexpr auto kSubscriptionsSettle = std::chrono::milliseconds(200);
  std::uint64_t seen = impl_->subscriptions_made.load();
  auto last = clock::now();
  while (clock::now() - last < kSubscriptionsSettle && clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (const std::uint64_t now_made = impl_->subscriptions_made.load(); now_made != seen) {
      seen = now_made;
      last = clock::now();
    }
  }
  return true;
}

unsigned short FoxgloveServer::port() const {
  beast::error_code ec;
  return impl_->acceptor.local_endpoint(ec).port();
}

std::string FoxgloveServer::url() const {
  return "ws://" + craneassist::net::client_host_port(impl_->options.address, port());
}

control::CycleObserver& FoxgloveServer::observer() {
  return impl_->observer;
}

ServerCounters FoxgloveServer::counters() const {
  const Impl& i = *impl_;
  return {i.clients_connected.load(),  i.subscriptions_made.load(),
          i.messages_sent.load(),      i.messages_dropped.load(),
          i.cycles.dropped(),          i.client_malformed.load(),
          i.client_unsupported.load(), i.refused.load()};
}

std::string FoxgloveServer::report() const {
  const ServerCounters c = counters();
  using std::to_string;
  return "  foxglove: " + to_string(c.clients_connected) + " clients, " +
         to_string(c.subscriptions) + " subscriptions, " + to_string(c.messages_sent) +
         " messages sent (" + to_string(c.messages_dropped) + " dropped: a client behind; " +
         to_string(c.cycles_dropped) + " cycles dropped), client messages " +
         to_string(c.client_malformed) + " malformed, " + to_string(c.client_unsupported) +
         " unsupported, " + to_string(c.refused) + " connections refused";
}

}  // namespace craneassist::foxglove
