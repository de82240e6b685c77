// What the two Boost.Beast servers of craneassist share (the web view, app/web; the Foxglove
// WebSocket server, app/foxglove): listening on an address, accepting connections into
// sessions, running the I/O thread, and the address a client should use.
#pragma once

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <future>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace craneassist::net {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

// Opens, binds and listens; throws std::runtime_error "WHO: cannot listen on ADDRESS:PORT: step:
// why" (a port in use, an address not of this host) or "WHO: bad listen address".
inline void listen(tcp::acceptor& acceptor, const std::string& address, unsigned short port,
                   const char* who) {
  boost::system::error_code ec;
  const auto ip = asio::ip::make_address(address, ec);
  if (ec) throw std::runtime_error(std::string(who) + ": bad listen address '" + address + "'");
  const tcp::endpoint endpoint(ip, port);
  auto fail = [&](const char* what) {
    throw std::runtime_error(std::string(who) + ": cannot listen on " + address + ":" +
                             std::to_string(port) + ": " + what + ": " + ec.message());
  };
  acceptor.open(endpoint.protocol(), ec);
  if (ec) fail("open");
  acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  acceptor.bind(endpoint, ec);
  if (ec) fail("bind");
  acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) fail("listen");
}

// Accepts connections for ever (until the acceptor closes): each socket to make_session(socket).
template <class MakeSession>
void accept_into(tcp::acceptor& acceptor, MakeSession make_session) {
  acceptor.async_accept([&acceptor, make_session](boost::system::error_code ec, tcp::socket s) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) make_session(std::move(s));
    accept_into(acceptor, make_session);
  });
}

// The I/O thread: runs ioc until it has no work; a handler that throws (out of memory) is
// logged and the loop goes on. `stopped` is set when it ends.
inline std::thread run_io_thread(asio::io_context& ioc, std::promise<void>& stopped,
                                 const char* who) {
  return std::thread([&ioc, &stopped, who] {
    for (;;) {
      try {
        ioc.run();
        break;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "craneassist: %s: %s\n", who, e.what());
      }
    }
    stopped.set_value();
  });
}

// Ends the I/O thread: `shutdown` posted to it (close the acceptor and the sessions), then at
// most wait_s for the thread to run out of work before the context is stopped.
template <class Shutdown>
void stop_io_thread(asio::io_context& ioc, std::thread& thread, std::promise<void>& stopped,
                    Shutdown shutdown, double wait_s) {
  if (!thread.joinable()) return;
  asio::post(ioc, shutdown);
  if (stopped.get_future().wait_for(std::chrono::duration<double>(wait_s)) !=
      std::future_status::ready) {
    ioc.stop();
  }
  thread.join();
}

// `bytes` random bytes from /dev/urandom as lowercase hex (a session's token or id); nullopt when
// they cannot be read.
inline std::optional<std::string> random_hex(std::size_t bytes) {
  std::vector<unsigned char> raw(bytes);
  std::ifstream urandom("/dev/urandom", std::ios::binary);
  urandom.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size()));
  if (!urandom) return std::nullopt;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (const unsigned char b : raw) {
    out += kHex[b >> 4];
    out += kHex[b & 15];
  }
  return out;
}

// One HTTP connection of a server (CRTP: Derived is the server's session, which answers in
// handle(request)): reads a request of at most 8 kB header and 8 kB body within 30 s; a read
// that fails (the client left, too large, too slow) shuts the connection.
template <class Derived>
class HttpConnection : public std::enable_shared_from_this<Derived> {
 public:
  explicit HttpConnection(tcp::socket&& socket) : stream_(std::move(socket)) {}

  void read() {
    parser_.emplace();
    parser_->header_limit(8192);
    parser_->body_limit(8192);
    stream_.expires_after(std::chrono::seconds(30));
    boost::beast::http::async_read(
        stream_, buffer_, *parser_,
        [self = this->shared_from_this()](boost::system::error_code ec, std::size_t) {
          if (ec) {
            self->shutdown();
            return;
          }
          self->handle(self->parser_->release());
        });
  }

 protected:
  void shutdown() {
    boost::system::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  }

  boost::beast::tcp_stream stream_;
  boost::beast::flat_buffer buffer_;
  std::optional<boost::beast::http::request_parser<boost::beast::http::string_body>> parser_;
};

// "HOST:PORT" for a client on this host: a listener on every interface (0.0.0.0, ::) is reached
// at 127.0.0.1; an IPv6 address in brackets.
inline std::string client_host_port(const std::string& address, unsigned short port) {
  std::string host = address;
  if (host == "0.0.0.0" || host == "::") host = "127.0.0.1";
  if (host.find(':') != std::string::npos) host = "[" + host + "]";
  return host + ":" + std::to_string(port);
}

}  // namespace craneassist::net
