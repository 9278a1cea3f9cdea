#include "monitor/server.h"

#include <civetweb.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>

#include "monitor/web_assets.h"

namespace eamos::monitor {

namespace {

// Beyond this a mission keeps flying and the page misses events (it is told how many).
constexpr std::size_t max_history = 5'000'000;
// The most events in one WebSocket message: a browser parses each message in one go.
constexpr std::size_t max_batch = 20'000;
constexpr std::size_t max_clients = 32;

bool valid_host_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == ':' || c == '[' || c == ']';
}

bool is_loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1" || host == "[::1]";
}

// The Host header without its port ("127.0.0.1:8080" → "127.0.0.1"), and its port.
void split_host(const std::string& header, std::string& host, std::string& port) {
  std::size_t colon = header.rfind(':');
  std::size_t bracket = header.rfind(']');
  if (colon == std::string::npos || (bracket != std::string::npos && colon < bracket)) {
    host = header;
    port = "";
    return;
  }
  host = header.substr(0, colon);
  port = header.substr(colon + 1);
}

void send_status(mg_connection* conn, int code, const char* text) {
  mg_printf(conn,
            "HTTP/1.1 %d %s\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: %zu\r\n"
            "Connection: close\r\n\r\n%s",
            code, text, std::strlen(text), text);
}

// Unix ms to the microsecond: enough for a latency in ms, short on the wire.
std::string stamp_text(double ms) {
  if (ms <= 0) return "0";
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", ms);
  return text;
}

}  // namespace

bool parse_endpoint(const std::string& text, Endpoint& out, std::string& error) {
  std::string host = "127.0.0.1", port = text;
  std::size_t colon = text.rfind(':');
  if (colon != std::string::npos) {
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  bool host_ok = !host.empty() && host.size() <= 255;
  for (char c : host) host_ok = host_ok && valid_host_char(c);
  if (!host_ok) {
    error = "'" + text + "' is not [HOST:]PORT; give e.g. 8080 or 127.0.0.1:8080 (0.0.0.0:8080 to serve other machines)";
    return false;
  }
  bool port_ok = !port.empty() && port.size() <= 5;
  for (char c : port) port_ok = port_ok && std::isdigit(static_cast<unsigned char>(c));
  if (!port_ok || std::stoi(port) > 65535) {
    error = "'" + port + "' is not a port number; give 0 to 65535 (0: any free port)";
    return false;
  }
  out.host = host;
  out.port = std::stoi(port);
  return true;
}

MonitorServer::MonitorServer() { mg_init_library(0); }

MonitorServer::~MonitorServer() {
  stop();
  mg_exit_library();
}

void MonitorServer::set_mission(std::string mission_json) { mission_json_ = std::move(mission_json); }

bool MonitorServer::start(const Endpoint& at, std::string& error) {
  std::string ports = at.host.find(':') != std::string::npos && at.host.front() != '['
                          ? "[" + at.host + "]:" + std::to_string(at.port)
                          : at.host + ":" + std::to_string(at.port);
  const char* options[] = {"listening_ports", ports.c_str(), "num_threads", "40",
                           "enable_directory_listing", "no", "request_timeout_ms", "10000",
                           "enable_websocket_ping_pong", "yes",
                           // Each live event is a small write: with Nagle's algorithm one waits for
                           // the browser's delayed ACK of the one before (tens of ms on loopback).
                           "tcp_nodelay", "1", nullptr};
  mg_callbacks callbacks{};
  // civetweb would print to stderr; the error text is returned instead.
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };
  context_ = mg_start(&callbacks, this, options);
  if (!context_) {
    error = "cannot serve the monitor on " + ports + " (in use, or not an address of this machine); "
            "choose another with --monitor HOST:PORT or --port";
    return false;
  }
  mg_server_port bound[4];
  int n = mg_get_server_ports(context_, 4, bound);
  port_ = n > 0 ? bound[0].port : at.port;
  loopback_ = is_loopback(at.host);
  std::string shown = at.host == "0.0.0.0" || at.host == "::" ? "127.0.0.1" : at.host;
  if (shown.find(':') != std::string::npos && shown.front() != '[') shown = "[" + shown + "]";
  url_ = "http://" + shown + ":" + std::to_string(port_) + "/";
  mg_set_request_handler(context_, "/", &MonitorServer::on_http, this);
  mg_set_websocket_handler(context_, "/ws", &MonitorServer::on_ws_connect, &MonitorServer::on_ws_ready,
                           &MonitorServer::on_ws_data, &MonitorServer::on_ws_close, this);
  sender_ = std::thread([this] { send_loop(); });
  return true;
}

void MonitorServer::stop() {
  {
    std::lock_guard<std::mutex> lock(events_mutex_);
    stopping_ = true;
  }
  events_changed_.notify_all();
  if (sender_.joinable()) sender_.join();
  if (context_) mg_stop(context_);
  context_ = nullptr;
}

void MonitorServer::append(std::string event_json, double emitted_ms) {
  {
    std::lock_guard<std::mutex> lock(events_mutex_);
    if (events_.size() >= max_history) {
      ++dropped_;
      return;
    }
    events_.push_back(Event{std::move(event_json), emitted_ms});
    news_ = true;
  }
  events_changed_.notify_one();
}

void MonitorServer::finish() {
  {
    std::lock_guard<std::mutex> lock(events_mutex_);
    finished_ = true;
    news_ = true;
  }
  events_changed_.notify_one();
}

std::size_t MonitorServer::event_count() const {
  std::lock_guard<std::mutex> lock(events_mutex_);
  return events_.size();
}

std::size_t MonitorServer::dropped_count() const {
  std::lock_guard<std::mutex> lock(events_mutex_);
  return dropped_;
}

std::size_t MonitorServer::client_count() const {
  std::lock_guard<std::mutex> lock(clients_mutex_);
  return clients_.size();
}

// A page on another site must not read the mission through a name that points here
// (DNS rebinding): on a loopback address only loopback names are served.
bool MonitorServer::host_allowed(const mg_connection* conn) const {
  if (!loopback_) return true;
  const char* header = mg_get_header(conn, "Host");
  if (!header) return false;
  std::string host, port;
  split_host(header, host, port);
  return is_loopback(host) && port == std::to_string(port_);
}

int MonitorServer::on_http(mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  const mg_request_info* info = mg_get_request_info(conn);
  bool head = std::strcmp(info->request_method, "HEAD") == 0;
  if (std::strcmp(info->request_method, "GET") != 0 && !head) {
    send_status(conn, 405, "The monitor only shows: GET and the WebSocket, nothing that changes anything.");
    return 405;
  }
  if (!self->host_allowed(conn)) {
    send_status(conn, 403, "Open the monitor through the address it printed.");
    return 403;
  }
  const WebAsset* asset = find_web_asset(info->local_uri ? info->local_uri : "");
  if (!asset) {
    send_status(conn, 404, "Not found.");
    return 404;
  }
  mg_printf(conn,
            "HTTP/1.1 200 OK\r\nContent-Type: %s\r\nContent-Length: %zu\r\nCache-Control: no-store\r\n"
            "X-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\nReferrer-Policy: no-referrer\r\n"
            "Content-Security-Policy: default-src 'self'; img-src 'self' data:; style-src 'self' 'unsafe-inline'; "
            "connect-src 'self'; frame-ancestors 'none'\r\n\r\n",
            asset->content_type, asset->size);
  if (!head) mg_write(conn, asset->data, asset->size);
  return 200;
}

int MonitorServer::on_ws_connect(const mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  if (!self->host_allowed(conn)) return 1;  // non-zero refuses the connection
  const char* origin = mg_get_header(conn, "Origin");
  const char* host = mg_get_header(conn, "Host");
  if (origin && host && std::string(origin) != std::string("http://") + host) return 1;
  std::lock_guard<std::mutex> lock(self->clients_mutex_);
  if (self->clients_.size() >= max_clients) return 1;
  self->clients_[conn] = Client{};
  return 0;
}

void MonitorServer::on_ws_ready(mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  {
    std::lock_guard<std::mutex> lock(self->clients_mutex_);
    auto it = self->clients_.find(conn);
    if (it != self->clients_.end()) it->second.ready = true;
  }
  {
    std::lock_guard<std::mutex> lock(self->events_mutex_);
    self->news_ = true;
  }
  self->events_changed_.notify_one();
}

// The page may say hello; nothing it sends is read, so nothing it sends can change anything.
int MonitorServer::on_ws_data(mg_connection*, int bits, char*, std::size_t, void*) {
  const int opcode = bits & 0x0f;
  return opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE ? 0 : 1;
}

void MonitorServer::on_ws_close(const mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  std::lock_guard<std::mutex> lock(self->clients_mutex_);
  self->clients_.erase(conn);
}

void MonitorServer::send_loop() {
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(events_mutex_);
      // Woken by news, also news that came while the last batch was being written (a notify
      // then finds nobody waiting: waiting for it anyway cost up to the timeout per event).
      events_changed_.wait_for(lock, std::chrono::milliseconds(50), [this] { return news_ || stopping_; });
      news_ = false;
      if (stopping_) return;
    }
    std::lock_guard<std::mutex> lock(clients_mutex_);
    for (auto& [conn, client] : clients_)
      if (client.ready) send_pending(const_cast<mg_connection*>(conn), client);
  }
}

void MonitorServer::send_pending(mg_connection* conn, Client& client) {
  if (!client.sent_mission) {
    std::string hello = "{\"type\":\"mission\",\"mission\":" + (mission_json_.empty() ? "{}" : mission_json_) + "}";
    if (mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_TEXT, hello.data(), hello.size()) <= 0) return;
    client.sent_mission = true;
  }
  for (;;) {
    std::string batch, emitted;
    std::size_t from = client.cursor, count = 0, dropped = 0;
    bool finished = false;
    {
      std::lock_guard<std::mutex> lock(events_mutex_);
      std::size_t to = std::min(events_.size(), from + max_batch);
      count = to - from;
      for (std::size_t i = from; i < to; ++i) {
        batch += i == from ? "" : ",";
        batch += events_[i].json;
        emitted += i == from ? "" : ",";
        emitted += stamp_text(events_[i].emitted_ms);
      }
      finished = finished_ && to == events_.size();
      dropped = dropped_;
    }
    if (count > 0) {
      double sent_ms = std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
      std::string message = "{\"type\":\"events\",\"sent\":" + stamp_text(sent_ms) + ",\"from\":" + std::to_string(from) + ",\"dropped\":" +
                            std::to_string(dropped) + ",\"events\":[" + batch + "],\"emitted\":[" + emitted + "]}";
      if (mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_TEXT, message.data(), message.size()) <= 0) return;
      client.cursor = from + count;
    }
    if (finished && !client.sent_finish) {
      std::string message = "{\"type\":\"finished\"}";
      if (mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_TEXT, message.data(), message.size()) <= 0) return;
      client.sent_finish = true;
    }
    if (count < max_batch) return;
  }
}

}  // namespace eamos::monitor
