// connection.cpp — see connection.hpp.
#include "connection.hpp"

#include <linux/sockios.h>
#include <netdb.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace hmpm::server::http {
namespace {

using SteadyClock = std::chrono::steady_clock;

thread_local StreamLimit stream_limit = StreamLimit::none;
thread_local std::string malformed_reason;
thread_local bool close_requested = false;
thread_local bool routed = false;

SteadyClock::time_point after(double seconds) {
  return SteadyClock::now() +
         std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(seconds));
}

// Milliseconds left until `deadline`, at most `cap_ms`; 0 once it passed.
int ms_until(SteadyClock::time_point deadline, int cap_ms) {
  const auto left =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SteadyClock::now()).count();
  return static_cast<int>(std::clamp<long long>(left, 0, cap_ms));
}

// Waits for `events` on `sock`; true when it came.
bool wait_for(socket_t sock, short events, int timeout_ms) {
  pollfd p{sock, events, 0};
  int n = 0;
  do {
    n = ::poll(&p, 1, timeout_ms);
  } while (n < 0 && errno == EINTR);
  return n > 0;
}

void address_of(socket_t sock, bool peer, std::string& ip, int& port) {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  auto* sa = reinterpret_cast<sockaddr*>(&addr);
  if ((peer ? ::getpeername(sock, sa, &len) : ::getsockname(sock, sa, &len)) != 0) return;
  std::array<char, NI_MAXHOST> host{};
  std::array<char, NI_MAXSERV> serv{};
  if (::getnameinfo(sa, len, host.data(), host.size(), serv.data(), serv.size(),
                    NI_NUMERICHOST | NI_NUMERICSERV) == 0) {
    ip = host.data();
    port = std::atoi(serv.data());
  }
}

bool is_token_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (std::isalnum(u) != 0) return true;
  return std::string_view("!#$%&'*+-.^_`|~").find(c) != std::string_view::npos;
}

bool same_name(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view trim_blanks(std::string_view v) {
  while (!v.empty() && (v.front() == ' ' || v.front() == '\t')) v.remove_prefix(1);
  while (!v.empty() && (v.back() == ' ' || v.back() == '\t')) v.remove_suffix(1);
  return v;
}

// One connection's byte stream as httplib's parser sees it (one object for
// the connection's life, so pipelined bytes stay buffered between requests).
class DeadlineStream final : public httplib::Stream {
 public:
  DeadlineStream(socket_t sock, const std::atomic<socket_t>& listener,
                 const ConnectionLimits& limits, int read_timeout_ms)
      : sock_(sock), listener_(listener), limits_(limits), read_timeout_ms_(read_timeout_ms) {}

  // A new request: its head is due within the head timeout from now.
  void begin_request() {
    in_head_ = true;
    head_bytes_ = 0;
    head_.clear();
    head_lines_ = 0;
    line_length_ = 0;
    deadline_ = after(limits_.head_timeout_s);
    stream_limit = StreamLimit::none;
    routed = false;
  }

  bool has_buffered() const { return begin_ < end_; }

  bool is_readable() const override {
    return has_buffered() || wait_for(sock_, POLLIN, ms_until(deadline_, read_timeout_ms_));
  }

  bool is_writable() const override {
    // No peek for EOF: a client that half-closed after sending still reads.
    return writable_or_draining();
  }

  ssize_t read(char* ptr, std::size_t size) override {
    if (!has_buffered() && !fill()) return -1;
    std::size_t n = std::min(size, end_ - begin_);
    if (in_head_) {
      // Deliver up to the blank line that ends the head at most, counting.
      for (std::size_t i = 0; i < n; ++i) {
        const char c = buffer_[begin_ + i];
        ++head_bytes_;
        head_.push_back(c);
        if (c == '\n') {
          ++head_lines_;
          const bool blank = line_length_ == 0;
          line_length_ = 0;
          if (blank) {
            // The whole head is here: refuse it before httplib parses it
            // its own, laxer way.
            malformed_reason = head_problem(head_);
            if (!malformed_reason.empty()) {
              stream_limit = StreamLimit::malformed_head;
              return -1;
            }
            in_head_ = false;
            deadline_ = after(limits_.body_timeout_s);
            n = i + 1;
            break;
          }
        } else if (c != '\r') {
          ++line_length_;
        }
        // The request line and headers, plus the blank line.
        if (head_bytes_ > limits_.max_head_bytes || head_lines_ > limits_.max_header_count + 1) {
          stream_limit = StreamLimit::head_too_large;
          return -1;
        }
      }
    }
    std::copy_n(buffer_.data() + begin_, n, ptr);
    begin_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, std::size_t size) override {
    std::size_t done = 0;
    while (done < size) {
      if (!writable_or_draining()) return -1;
      const ssize_t n = ::send(sock_, ptr + done, size - done, MSG_NOSIGNAL);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return -1;
      done += static_cast<std::size_t>(n);
    }
    return static_cast<ssize_t>(done);
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    address_of(sock_, true, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    address_of(sock_, false, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  // Waits until the socket takes more bytes. A client that keeps reading,
  // however slowly or in bursts, is waited for: only a send queue that has
  // not shrunk for the stall timeout (a stalled reader) gives up, which ends
  // the connection and frees its thread. (POLLOUT alone comes only once a
  // third of the send buffer is free, which a slow reader takes long to make;
  // and a reader such as curl --limit-rate takes a burst, then pauses.)
  bool writable_or_draining() const {
    constexpr int slice_ms = 250;
    int queued = -1;
    auto stalled_at = after(limits_.send_stall_s);
    for (;;) {
      if (wait_for(sock_, POLLOUT, slice_ms)) return true;
      int now_queued = 0;
      if (::ioctl(sock_, SIOCOUTQ, &now_queued) != 0) return false;
      if (queued < 0 || now_queued < queued) stalled_at = after(limits_.send_stall_s);
      queued = now_queued;
      if (SteadyClock::now() >= stalled_at) return false;
    }
  }

  // Reads what the socket has, waiting until the current deadline (and at
  // most the read timeout between two arrivals, as httplib does); false on
  // a timeout, EOF or error, and for a head still incomplete when the server
  // stops (so a trickling client cannot hold up shutdown).
  bool fill() {
    begin_ = end_ = 0;
    constexpr int slice_ms = 200;
    for (;;) {
      const auto quiet_until = after(read_timeout_ms_ / 1000.0);
      bool ready = false;
      while (!ready) {
        if (in_head_ && listener_ == INVALID_SOCKET) return false;
        const int wait_ms =
            std::min(ms_until(deadline_, slice_ms), ms_until(quiet_until, slice_ms));
        if (wait_ms == 0) break;
        ready = wait_for(sock_, POLLIN, wait_ms);
      }
      if (!ready) {
        if (SteadyClock::now() >= deadline_) {
          stream_limit = in_head_ ? StreamLimit::head_timeout : StreamLimit::body_timeout;
        }
        return false;
      }
      const ssize_t n = ::recv(sock_, buffer_.data(), buffer_.size(), 0);
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n <= 0) return false;
      end_ = static_cast<std::size_t>(n);
      return true;
    }
  }

  socket_t sock_;
  const std::atomic<socket_t>& listener_;  ///< INVALID_SOCKET once the server stops
  const ConnectionLimits& limits_;
  int read_timeout_ms_;
  std::array<char, 16384> buffer_{};
  std::size_t begin_ = 0;
  std::size_t end_ = 0;
  bool in_head_ = true;
  std::size_t head_bytes_ = 0;
  std::string head_;  ///< the head so far (at most max_head_bytes)
  std::size_t head_lines_ = 0;
  std::size_t line_length_ = 0;
  SteadyClock::time_point deadline_ = SteadyClock::now();
};

// httplib's task queue, elastic: `core` threads at start, one more whenever
// a task arrives and none is idle, up to `max`; threads are kept once made.
class ElasticPool final : public httplib::TaskQueue {
 public:
  ElasticPool(std::size_t core, std::size_t max) : max_(std::max(core, max)) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < core; ++i) spawn();
  }

  void enqueue(std::function<void()> fn) override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tasks_.push_back(std::move(fn));
      if (idle_ < tasks_.size() && threads_.size() < max_) spawn();
    }
    wake_.notify_one();
  }

  void shutdown() override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

 private:
  void spawn() {
    threads_.emplace_back([this] {
      std::unique_lock<std::mutex> lock(mutex_);
      for (;;) {
        ++idle_;
        wake_.wait(lock, [this] { return stopping_ || !tasks_.empty(); });
        --idle_;
        if (tasks_.empty()) return;  // stopping, and nothing left
        std::function<void()> task = std::move(tasks_.front());
        tasks_.pop_front();
        lock.unlock();
        task();
        lock.lock();
      }
    });
  }

  std::size_t max_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> tasks_;
  std::vector<std::thread> threads_;
  std::size_t idle_ = 0;
  bool stopping_ = false;
};

// Reads and discards what the client still sends, until EOF or `seconds`.
void drain(socket_t sock, double seconds) {
  const auto until = after(seconds);
  std::array<char, 16384> sink{};
  while (wait_for(sock, POLLIN, ms_until(until, 1000))) {
    if (::recv(sock, sink.data(), sink.size(), 0) <= 0) return;
  }
}

// The answer beyond max_connections, written without httplib.
std::string busy_response() {
  const std::string body =
      R"({"type":"too-many-connections","title":"Too many connections",)"
      R"("status":503,"detail":"the server is serving its maximum of connections; retry"})";
  return "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/problem+json\r\n"
         "Retry-After: 1\r\nConnection: close\r\nContent-Length: " +
         std::to_string(body.size()) + "\r\n\r\n" + body;
}

int to_ms(time_t sec, time_t usec) {
  return static_cast<int>(sec * 1000 + usec / 1000);
}

}  // namespace

StreamLimit current_stream_limit() {
  return stream_limit;
}

const std::string& malformed_head_reason() {
  return malformed_reason;
}

std::string head_problem(std::string_view head) {
  if (head.find('\0') != std::string_view::npos) return "the request head holds a NUL byte";
  for (std::size_t i = 0; i < head.size(); ++i) {
    if (head[i] == '\n' && (i == 0 || head[i - 1] != '\r'))
      return "a line of the request head ends in LF without CR";
    if (head[i] == '\r' && (i + 1 == head.size() || head[i + 1] != '\n'))
      return "the request head holds a CR that does not end a line";
  }
  std::size_t pos = head.find("\r\n");
  const std::string_view request_line = head.substr(0, pos);
  if (request_line.empty()) return "the request line is empty";
  const auto space = request_line.rfind(' ');
  const std::string_view version =
      space == std::string_view::npos ? std::string_view() : request_line.substr(space + 1);
  std::size_t hosts = 0;
  std::string_view length;
  pos += 2;
  while (pos < head.size()) {
    const std::size_t end = head.find("\r\n", pos);
    const std::string_view line = head.substr(pos, end - pos);
    pos = end + 2;
    if (line.empty()) break;  // the blank line that ends the head
    if (line.front() == ' ' || line.front() == '\t')
      return "a header line is folded onto the one before (obs-fold)";
    const auto colon = line.find(':');
    if (colon == std::string_view::npos) return "a header line has no colon";
    const std::string_view name = line.substr(0, colon);
    if (name.empty() || !std::all_of(name.begin(), name.end(), is_token_char)) {
      return "header field name '" + std::string(name.substr(0, 64)) +
             "' is not a token (white space before the colon?)";
    }
    const std::string_view value = line.substr(colon + 1);
    for (const char c : value) {
      const auto u = static_cast<unsigned char>(c);
      if ((u < 0x20 && c != '\t') || u == 0x7f)
        return "header " + std::string(name) + " holds a control character";
    }
    if (same_name(name, "Host")) {
      ++hosts;
      if (trim_blanks(value).empty()) return "the Host header is empty";
    }
    if (same_name(name, "Content-Length")) {
      // Several Content-Length lines (or a list in one) must agree.
      std::string_view rest = value;
      while (true) {
        const auto comma = rest.find(',');
        const std::string_view item = trim_blanks(rest.substr(0, comma));
        if (!length.empty() && item != length) return "two different Content-Length values";
        if (length.empty()) length = item;
        if (comma == std::string_view::npos) break;
        rest = rest.substr(comma + 1);
      }
    }
  }
  if (version == "HTTP/1.1" && hosts != 1)
    return hosts == 0 ? "an HTTP/1.1 request needs a Host header"
                      : "the request has more than one Host header";
  if (hosts > 1) return "the request has more than one Host header";
  return {};
}

void note_routed() {
  routed = true;
}

bool request_routed() {
  return routed;
}

void close_after_response() {
  close_requested = true;
}

HardenedServer::HardenedServer(ConnectionLimits limits) : limits_(limits) {
  // A connection beyond max_connections still needs a thread to be refused.
  const std::size_t max_threads = limits_.max_connections + 8;
  new_task_queue = [core = limits_.core_threads, max_threads] {
    return new ElasticPool(core, max_threads);
  };
}

void HardenedServer::widen_backlog(int backlog) {
  const socket_t sock = svr_sock_;
  if (sock != INVALID_SOCKET) ::listen(sock, backlog);
}

bool HardenedServer::process_and_close_socket(socket_t sock) {
  struct Count {
    std::atomic<std::size_t>& n;
    ~Count() { --n; }
  } counted{open_};
  bool ok = false;
  if (++open_ > limits_.max_connections) {
    const std::string busy = busy_response();
    ::send(sock, busy.data(), busy.size(), MSG_NOSIGNAL);
  } else {
    DeadlineStream stream(sock, svr_sock_, limits_, to_ms(read_timeout_sec_, read_timeout_usec_));
    const int keep_alive_ms = static_cast<int>(keep_alive_timeout_sec_ * 1000);
    for (std::size_t count = keep_alive_max_count_; count > 0; --count) {
      // Idle between requests: wait in slices, so a stopping server is seen.
      const auto idle_until = after(keep_alive_ms / 1000.0);
      bool ready = stream.has_buffered();
      while (!ready && svr_sock_ != INVALID_SOCKET && ms_until(idle_until, 100) > 0) {
        ready = wait_for(sock, POLLIN, ms_until(idle_until, 100));
      }
      if (!ready || svr_sock_ == INVALID_SOCKET) break;
      stream.begin_request();
      close_requested = false;
      bool connection_closed = false;
      ok = process_request(stream, count == 1, connection_closed, nullptr);
      if (close_requested) {
        // The body was not read: stop sending, let the client finish and see
        // the answer, then close (a close with unread data would reset it).
        ::shutdown(sock, SHUT_WR);
        drain(sock, limits_.linger_s);
        break;
      }
      if (!ok || connection_closed) break;
    }
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return ok;
}

}  // namespace hmpm::server::http
