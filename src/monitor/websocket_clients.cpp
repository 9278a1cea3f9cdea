// The monitor's WebSocket pages: each has a writer thread of its own that sends it the mission
// and then the events from its own cursor into the one shared history, so a page that stops
// reading holds up only its own writer. A watchdog drops the pages that fall behind or stop
// answering; a new page may take the place of one that is not answering. See
// docs/monitor.md, "Many browsers, slow ones".
#include <civetweb.h>
#include <dirent.h>
#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "monitor/server.h"

namespace eamos::monitor {

namespace {

// The most events in one WebSocket message: a browser parses each message in one go.
constexpr std::size_t max_batch = 20'000;
// A page whose handshake never completed (civetweb then calls neither ready nor close) is
// forgotten after this.
constexpr std::chrono::seconds handshake_limit{10};

// Unix ms to the microsecond: enough for a latency in ms, short on the wire.
std::string stamp_text(double ms) {
  if (ms <= 0) return "0";
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", ms);
  return text;
}

double wall_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool write_frame(mg_connection* conn, int opcode, const std::string& data) {
  int n = mg_websocket_write(conn, opcode, data.data(), data.size());
  return data.empty() ? n > 0 : n == static_cast<int>(data.size());
}

std::string numeric_host(const sockaddr_storage& a, socklen_t len, int& port) {
  char host[NI_MAXHOST], service[NI_MAXSERV];
  if (getnameinfo(reinterpret_cast<const sockaddr*>(&a), len, host, sizeof host, service, sizeof service,
                  NI_NUMERICHOST | NI_NUMERICSERV) != 0)
    return "";
  port = std::atoi(service);
  return host;
}

// civetweb gives no way to close a server connection from another thread, nor its socket:
// the socket is the one of this process whose ends are the page's address and our port.
// Shutting it down makes civetweb's own read of it end, which closes the connection.
int find_socket(const mg_connection* conn, int local_port) {
  const mg_request_info* info = mg_get_request_info(conn);
  DIR* dir = opendir("/proc/self/fd");
  if (!info || !dir) return dir ? (closedir(dir), -1) : -1;
  int found = -1;
  while (dirent* entry = readdir(dir)) {
    int fd = std::atoi(entry->d_name);
    if (fd <= 2 || fd == dirfd(dir)) continue;
    sockaddr_storage peer{}, local{};
    socklen_t peer_len = sizeof peer, local_len = sizeof local;
    if (getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &peer_len) != 0 ||
        getsockname(fd, reinterpret_cast<sockaddr*>(&local), &local_len) != 0)
      continue;
    int peer_port = 0, our_port = 0;
    std::string peer_host = numeric_host(peer, peer_len, peer_port);
    numeric_host(local, local_len, our_port);
    if (our_port == local_port && peer_port == info->remote_port && peer_host == info->remote_addr) {
      found = fd;
      break;
    }
  }
  closedir(dir);
  return found;
}

}  // namespace

struct MonitorServer::Batch {
  std::vector<const Event*> events;
  std::size_t from = 0, dropped = 0;
  bool finished = false;
};

int MonitorServer::on_ws_connect(const mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  if (!self->host_allowed(conn)) return 1;  // non-zero refuses the connection
  const char* origin = mg_get_header(conn, "Origin");
  const char* host = mg_get_header(conn, "Host");
  if (origin && host && std::string(origin) != std::string("http://") + host) return 1;
  return self->admit(conn) ? 0 : 1;
}

// A page is taken when there is room, or in the place of the one that has said nothing
// longest among those not answering (no hello yet, or a ping left unanswered); else refused.
bool MonitorServer::admit(const mg_connection* conn) {
  int fd = find_socket(conn, port_);  // before the lock: it reads /proc
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) return false;
  Clock::time_point now = Clock::now();
  int active = 0;
  Client* victim = nullptr;
  auto silent_since = [](const Client& c) { return c.said_hello ? c.ping_sent : c.connected; };
  for (auto& [key, c] : clients_) {
    if (c->closing) continue;
    ++active;
    if (unresponsive(*c, now) && (!victim || silent_since(*c) < silent_since(*victim))) victim = c.get();
  }
  if (active >= limits_.max_websockets) {
    if (!victim) return false;
    drop(*victim);
  }
  auto client = std::make_unique<Client>();
  client->conn = const_cast<mg_connection*>(conn);
  client->fd = fd;
  client->connected = client->last_ping = now;
  client->joined_at = events_.size();
  clients_[conn] = std::move(client);
  return true;
}

bool MonitorServer::unresponsive(const Client& c, Clock::time_point now) const {
  if (!c.said_hello) return now - c.connected > std::chrono::milliseconds(250);
  return c.ping_outstanding && now - c.ping_sent > std::chrono::seconds(1);
}

void MonitorServer::on_ws_ready(mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  std::lock_guard<std::mutex> lock(self->mutex_);
  auto it = self->clients_.find(conn);
  if (it == self->clients_.end() || it->second->closing) return;
  Client* client = it->second.get();
  client->ready = true;
  client->writer = std::thread([self, client] { self->write_loop(client); });
}

// What a page sends is not read: it only says the page is there (its hello, the answers to
// pings), so nothing it sends can change anything. A page the server has forgotten is closed.
int MonitorServer::on_ws_data(mg_connection* conn, int bits, char*, std::size_t, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  std::lock_guard<std::mutex> lock(self->mutex_);
  auto it = self->clients_.find(conn);
  if (it == self->clients_.end() || it->second->closing) return 0;
  it->second->said_hello = true;
  it->second->ping_outstanding = false;
  return (bits & 0x0f) == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE ? 0 : 1;
}

void MonitorServer::on_ws_close(const mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  std::thread writer;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    auto it = self->clients_.find(conn);
    if (it == self->clients_.end()) return;
    Client& c = *it->second;
    c.closing = true;
    if (c.fd >= 0) shutdown(c.fd, SHUT_RDWR);  // a writer blocked on it returns now
    writer = std::move(c.writer);
  }
  self->changed_.notify_all();
  // The connection is civetweb's again once this returns: no writer may touch it after.
  if (writer.joinable()) writer.join();
  std::lock_guard<std::mutex> lock(self->mutex_);
  self->clients_.erase(conn);
}

// Under the lock: the page is dropped. Its socket is shut down, which ends its writer's
// write and civetweb's read; civetweb then closes it (on_ws_close).
void MonitorServer::drop(Client& c) {
  if (c.closing) return;
  c.closing = true;
  ++dropped_clients_;
  if (c.fd >= 0) shutdown(c.fd, SHUT_RDWR);
  changed_.notify_all();
}

void MonitorServer::write_loop(Client* c) {
  std::string hello = "{\"type\":\"mission\",\"mission\":" + (mission_json_.empty() ? "{}" : mission_json_) + "}";
  bool ok = write_frame(c->conn, MG_WEBSOCKET_OPCODE_TEXT, hello);
  std::unique_lock<std::mutex> lock(mutex_);
  auto due = [&] {
    Clock::time_point now = Clock::now();
    return stopping_ || c->closing || c->cursor < events_.size() || (finished_ && !c->sent_finish) ||
           (!c->ping_outstanding && now - c->last_ping >= std::chrono::duration<double>(limits_.ping_interval_s));
  };
  auto gone = [&] { return stopping_ || c->closing; };
  while (ok) {
    changed_.wait_for(lock, std::chrono::milliseconds(250), due);
    if (gone()) return;
    std::size_t before = c->cursor;
    ok = write_pending(c, lock);
    if (ok && c->cursor != before) changed_.wait_for(lock, std::chrono::duration<double>(limits_.batch_interval_s), gone);
  }
  drop(*c);  // a write that failed or made no progress for the header timeout
}

// Under the lock: the next events for `client` (pointers stay valid: the history only grows
// at its end, and a deque's elements do not move then).
void MonitorServer::take_batch(const Client& client, Batch& b) const {
  b.from = client.cursor;
  std::size_t to = std::min(events_.size(), b.from + max_batch);
  for (std::size_t i = b.from; i < to; ++i) b.events.push_back(&events_[i]);
  b.finished = finished_ && to == events_.size();
  b.dropped = dropped_;
}

// One message of events, the end, and a ping when one is due; written without the lock.
bool MonitorServer::write_pending(Client* c, std::unique_lock<std::mutex>& lock) {
  Batch b;
  take_batch(*c, b);
  Clock::time_point now = Clock::now();
  bool ping = !c->ping_outstanding && now - c->last_ping >= std::chrono::duration<double>(limits_.ping_interval_s);
  if (ping) c->ping_outstanding = true, c->ping_sent = c->last_ping = now;
  bool finish = b.finished && !c->sent_finish;
  lock.unlock();
  bool ok = true;
  if (!b.events.empty()) {
    std::string events, emitted;
    for (std::size_t i = 0; i < b.events.size(); ++i) {
      events += (i ? "," : "") + b.events[i]->json;
      emitted += (i ? "," : "") + stamp_text(b.events[i]->emitted_ms);
    }
    ok = write_frame(c->conn, MG_WEBSOCKET_OPCODE_TEXT,
                     "{\"type\":\"events\",\"sent\":" + stamp_text(wall_ms()) + ",\"from\":" + std::to_string(b.from) +
                         ",\"dropped\":" + std::to_string(b.dropped) + ",\"events\":[" + events + "],\"emitted\":[" +
                         emitted + "]}");
  }
  if (ok && finish) ok = write_frame(c->conn, MG_WEBSOCKET_OPCODE_TEXT, "{\"type\":\"finished\"}");
  if (ok && ping) ok = write_frame(c->conn, MG_WEBSOCKET_OPCODE_PING, "eamos");
  lock.lock();
  if (!ok) return false;
  c->cursor = b.from + b.events.size();
  if (finish) c->sent_finish = true;
  if (c->cursor >= c->joined_at && c->caught_up == Clock::time_point{}) c->caught_up = Clock::now();
  return true;
}

// Under the lock: why `c` must go, or null. A live event counts as late from when it was
// appended, or from when the page had its history, whichever is later (a long history is no lag).
const char* MonitorServer::why_drop(const Client& c, Clock::time_point now) const {
  if (!c.said_hello && now - c.connected > std::chrono::duration<double>(limits_.hello_timeout_s))
    return "said nothing after its handshake";
  if (c.ping_outstanding && now - c.ping_sent > std::chrono::duration<double>(limits_.answer_timeout_s))
    return "left a ping unanswered";
  std::size_t next = std::max(c.cursor, c.joined_at);
  if (c.caught_up != Clock::time_point{} && next < events_.size() &&
      now - std::max(events_[next].appended, c.caught_up) > std::chrono::duration<double>(limits_.max_lag_s))
    return "fell behind";
  return nullptr;
}

void MonitorServer::watch_loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    watch_wake_.wait_for(lock, std::chrono::milliseconds(200));
    Clock::time_point now = Clock::now();
    for (auto it = clients_.begin(); it != clients_.end();) {
      Client& c = *it->second;
      // civetweb gave up on its handshake (also one cut by drop()) and will not call us again;
      // it never had a writer.
      if (!c.ready && now - c.connected > handshake_limit) {
        it = clients_.erase(it);
        continue;
      }
      if (c.ready && !c.closing && why_drop(c, now)) drop(c);
      ++it;
    }
  }
}

}  // namespace eamos::monitor
