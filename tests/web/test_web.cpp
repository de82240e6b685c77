// The web view's server (app/web): its files, the crane description, the frame stream, the page's
// stick state as a command source, who may command, and the stick message parser. Real sockets
// on loopback, a Boost.Beast client.
#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <utility>

#include "../app/web/src/pad_message.hpp"
#include "craneassist/config/base_config.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/config/joystick_config.hpp"
#include "craneassist/web/web_server.hpp"

using namespace craneassist;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;

namespace {

struct Served {
  Served() : cfg(config::default_crane_config()) {
    web::WebOptions o;
    o.port = 0;
    o.token = "secret";
    server = std::make_unique<web::WebServer>(o, cfg);
  }
  config::CraneConfig cfg;
  std::unique_ptr<web::WebServer> server;
};

http::response<http::string_body> get(unsigned short port, const std::string& target) {
  net::io_context ioc;
  tcp::socket socket(ioc);
  socket.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  http::request<http::string_body> req(http::verb::get, target, 11);
  req.set(http::field::host, "127.0.0.1");
  http::write(socket, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(socket, buffer, res);
  return res;
}

class Page {
 public:
  Page(unsigned short port, const std::string& token) : ws_(ioc_) {
    ws_.next_layer().connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
    ws_.handshake("127.0.0.1", "/ws?token=" + token);
  }
  json read() {
    beast::flat_buffer buffer;
    ws_.read(buffer);
    return json::parse(beast::buffers_to_string(buffer.data()));
  }
  // The next message of a type (frames keep coming).
  json read(const std::string& type) {
    for (int i = 0; i < 200; ++i) {
      json m = read();
      if (m["type"] == type) return m;
    }
    return {};
  }
  void send(const std::string& text) { ws_.write(net::buffer(text)); }
  void close() { ws_.close(websocket::close_code::normal); }

 private:
  net::io_context ioc_;
  websocket::stream<tcp::socket> ws_;
};

// Polls until the source reports `state` (the server's thread hands the message over).
input::SourceState wait_for(input::CommandSource& source, input::SourceState state,
                            input::OperatorCommand& cmd) {
  input::SourceState s = input::SourceState::kNoData;
  for (int i = 0; i < 200 && (s = source.poll(cmd)) != state; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return s;
}

}  // namespace

TEST(WebServer, ServesThePageTheBundleAndTheCraneDescription) {
  Served s;
  const auto page = get(s.server->port(), "/");
  EXPECT_EQ(page.result(), http::status::ok);
  EXPECT_NE(page.body().find("<script src=\"app.js\">"), std::string::npos);
  const auto bundle = get(s.server->port(), "/app.js");
  EXPECT_EQ(bundle.result(), http::status::ok);
  EXPECT_GT(bundle.body().size(), 100000u);  // three.js inside
  const auto crane = json::parse(get(s.server->port(), "/crane.json").body());
  EXPECT_EQ(crane["joints"].size(), 4u);
  EXPECT_EQ(crane["joints"][3]["prismatic"], true);
  EXPECT_NEAR(crane["pump"]["max_power_w"].get<double>(), 35000.0, 1.0);
  EXPECT_EQ(get(s.server->port(), "/etc/passwd").result(), http::status::not_found);
  EXPECT_NE(s.server->url().find("?token=secret"), std::string::npos);
}

TEST(WebServer, StreamsTheCyclesWithTheCraneDrawnAsPoints) {
  Served s;
  Page page(s.server->port(), "secret");
  EXPECT_EQ(page.read("hello")["command"], "available");
  control::LogRow row;
  row.t = 1.5;
  row.q = {0.2, 0.5, -1.5, 1.0};
  row.status = "running";
  row.avail_speed_m_s = 1.25;
  row.avail_speed_resolved_m_s = 0.875;
  row.polytope_dim = 3;
  row.polytope_volume_m3s3 = 51.51;
  row.payload_estimate_kg = 448.5;
  row.payload_converged = true;
  row.load_moment_ratio = 0.5;
  row.rated_load_kg = 897.0;
  row.load_reach_m = 5.5;
  row.load_kg = 450.0;
  control::CycleTime time{};
  valves::MachineState state;
  valves::ValveCommand command;
  const control::CycleRecord rec{time,   state, command, row, control::CycleStatus::kRunning,
                                 nullptr};
  s.server->observer().on_cycle(rec);
  const json frame = page.read("frame");
  EXPECT_DOUBLE_EQ(frame["t"].get<double>(), 1.5);
  EXPECT_EQ(frame["points"].size(), 5u);     // base and four joint frames
  EXPECT_GE(frame["cylinders"].size(), 2u);  // lift, tilt, extension drawn
  EXPECT_EQ(frame["status"], "running");
  // The polytope's figures (the page's stick gauge, arrow and measure).
  EXPECT_EQ(frame["avail"], 1.25);
  EXPECT_EQ(frame["avail_resolved"], 0.875);
  EXPECT_EQ(frame["polytope"]["dim"], 3);
  EXPECT_EQ(frame["polytope"]["volume"], 51.51);
  EXPECT_EQ(frame["polytope"]["area"], 0.0);
  // The crane scale and the load moment (docs/loads.md); the truth is null on a machine.
  EXPECT_EQ(frame["load"]["estimate"], 448.5);
  EXPECT_EQ(frame["load"]["converged"], true);
  EXPECT_EQ(frame["load"]["ratio"], 0.5);
  EXPECT_EQ(frame["load"]["rated"], 897.0);
  EXPECT_EQ(frame["load"]["reach"], 5.5);
  EXPECT_EQ(frame["load"]["overload"], false);
  EXPECT_EQ(frame["load"]["truth"], 450.0);
  row.load_kg = std::numeric_limits<double>::quiet_NaN();
  s.server->observer().on_cycle(rec);
  EXPECT_TRUE(page.read("frame")["load"]["truth"].is_null());
}

// The crane on the wheeled base (sim --drive): the frame carries the base and places the crane's
// frame on it; without a base there is no base member.
TEST(WebServer, StreamsTheBaseAndTheCranesPlaceOnIt) {
  const config::CraneConfig cfg = config::default_crane_config();
  const config::BaseConfig base = config::default_base_config();
  web::WebOptions o;
  o.port = 0;
  o.token = "secret";
  o.base = &base.model;
  web::WebServer server(o, cfg);
  Page page(server.port(), "secret");
  EXPECT_EQ(page.read("hello")["command"], "available");
  control::LogRow row;
  row.t = 2.0;
  row.q = {0.2, 0.5, -1.5, 1.0};
  row.status = "running";
  row.base_present = true;
  row.base_pose = {3.0, 1.0, 0.5};
  row.base_velocity = {0.2, 0.05};
  row.base_flow_sum_m3s = 5e-4;
  row.base_flow_max_m3s = base.model.pump_max_flow_m3_s;
  server.publish(row);
  const json frame = page.read("frame");
  ASSERT_TRUE(frame.contains("base"));
  const json& b = frame["base"];
  EXPECT_DOUBLE_EQ(b["pose"][0].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(b["flow_sum"].get<double>(), 5e-4);
  // The crane's root: the mount point carried by the pose, in the view's frame (y up).
  const Eigen::Matrix3d& t = cfg.model.task_from_base;
  const Eigen::Vector3d mount =
      t * dynamics::world_from_crane_base(base.model, {3.0, 1.0, 0.5}, Eigen::Vector3d::Zero());
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(b["root_p"][i].get<double>(), mount[i], 1e-3);
  // A point in the crane's frame through root_r, root_p lands where the world mapping puts it.
  Eigen::Matrix3d r;
  for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = b["root_r"][i].get<double>();
  const Eigen::Vector3d p_task(4.0, 1.0, -0.5);
  const Eigen::Vector3d expected =
      t * dynamics::world_from_crane_base(base.model, {3.0, 1.0, 0.5}, t.transpose() * p_task);
  const Eigen::Vector3d drawn = r * p_task + mount;
  EXPECT_NEAR((drawn - expected).norm(), 0.0, 1e-3);  // the JSON has 5 significant digits
  ASSERT_EQ(b["boxes"].size(), 5u);                   // the chassis and four wheels
  EXPECT_EQ(b["boxes"][0]["kind"], "chassis");
  EXPECT_EQ(b["boxes"][1]["kind"], "wheel");

  row.base_present = false;
  row.t = 2.1;
  server.publish(row);
  json next = page.read("frame");
  for (int i = 0; i < 20 && next["t"].get<double>() < 2.05; ++i) next = page.read("frame");
  EXPECT_FALSE(next.contains("base"));
}

TEST(WebServer, ThePageIsAGamepadThatStopsWhenItLeaves) {
  Served s;
  const auto mapping = config::web_joystick_config().mapping;
  auto source = s.server->make_pad_source(mapping);
  input::OperatorCommand cmd;
  EXPECT_EQ(source->poll(cmd), input::SourceState::kNoData);
  {
    Page page(s.server->port(), "secret");
    page.read("hello");
    page.send(R"({"type":"pad","axes":[0,-1,0,0,0,0],"deadman":true})");  // left stick forward
    EXPECT_EQ(page.read("command")["state"], "yours");
    ASSERT_EQ(wait_for(*source, input::SourceState::kOk, cmd), input::SourceState::kOk);
    EXPECT_TRUE(cmd.deadman);
    source->begin_cycle(0.0, Eigen::Vector3d(5.0, 1.0, 0.0));
    source->poll(cmd);
    EXPECT_GT(cmd.v_m_s.x(), 0.3);  // out, along the radius
    EXPECT_NEAR(cmd.v_m_s.z(), 0.0, 1e-9);
    EXPECT_NEAR(cmd.stamp_s, input::steady_now_s(), 1.0);
    page.send("{not json");  // counted, not applied
    page.close();
  }
  EXPECT_EQ(wait_for(*source, input::SourceState::kDisconnected, cmd),
            input::SourceState::kDisconnected);
  const auto c = s.server->counters();
  EXPECT_EQ(c.pad_messages, 1u);
  EXPECT_EQ(c.pad_malformed, 1u);
  EXPECT_EQ(c.command_holders, 1u);
}

TEST(WebServer, WithoutTheTokenOrWhileAnotherPageHoldsItThePageOnlyWatches) {
  Served s;
  auto source = s.server->make_pad_source(config::web_joystick_config().mapping);
  Page stranger(s.server->port(), "guess");
  EXPECT_EQ(stranger.read("hello")["command"], "view");
  stranger.send(R"({"type":"pad","axes":[1],"deadman":true})");
  EXPECT_EQ(stranger.read("command")["state"], "refused");
  Page holder(s.server->port(), "secret");
  holder.read("hello");
  holder.send(R"({"type":"pad","axes":[0],"deadman":false})");
  EXPECT_EQ(holder.read("command")["state"], "yours");
  Page second(s.server->port(), "secret");
  second.read("hello");
  second.send(R"({"type":"pad","axes":[0],"deadman":true})");
  const json refused = second.read("command");
  EXPECT_EQ(refused["state"], "refused");
  EXPECT_NE(refused["why"].get<std::string>().find("another page"), std::string::npos);
  EXPECT_EQ(s.server->counters().pad_refused, 2u);
}

TEST(WebPadMessage, TakesOnlyAWellFormedStickState) {
  web::PadMessage m;
  ASSERT_TRUE(web::parse_pad_message(R"({"type":"pad","axes":[0.5,-1,0,1],"deadman":true})", m));
  EXPECT_DOUBLE_EQ(m.axes[0], 0.5);
  EXPECT_DOUBLE_EQ(m.axes[1], -1.0);
  EXPECT_DOUBLE_EQ(m.axes[4], 0.0);
  EXPECT_TRUE(m.deadman);
  for (const char* bad :
       {"", "null", "[]", "{", R"({"type":"pad"})", R"({"type":7,"axes":[],"deadman":true})",
        R"({"type":"pad","axes":[0],"deadman":1})", R"({"type":"pad","axes":[1.5],"deadman":true})",
        R"({"type":"pad","axes":["0"],"deadman":true})",
        R"({"type":"pad","axes":[0,0,0,0,0,0,0],"deadman":true})",
        R"({"type":"pad","axes":[1e999],"deadman":true})",
        R"({"type":"pad","axes":{"0":1},"deadman":true})",
        R"({"type":"cmd","axes":[0],"deadman":true})"}) {
    EXPECT_FALSE(web::parse_pad_message(bad, m)) << bad;
  }
}
