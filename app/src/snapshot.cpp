// Power-loss snapshots (app/snapshot.hpp; byte layout in docs/snapshot.md). Little-endian,
// as the LBRS file they embed.
#include "app/snapshot.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "geom/serialize.hpp"

namespace lbr::app {

static_assert(std::endian::native == std::endian::little, "the snapshot writer assumes a little-endian host");

namespace {

constexpr char kMagic[8] = {'L', 'B', 'R', 'S', 'N', 'A', 'P', '1'};
constexpr std::uint32_t kFormatVersion = 2;  // 1 is still read (no sender times, no record file)
const char* const kFiles[2] = {"snapshot-a.lbrsnap", "snapshot-b.lbrsnap"};

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    out.insert(out.end(), p, p + sizeof(T));
  }
  void bytes(const std::uint8_t* p, std::size_t n) { out.insert(out.end(), p, p + n); }
  std::vector<std::uint8_t> out;
};

class Reader {
 public:
  Reader(const std::vector<std::uint8_t>& b, std::size_t end, const std::string& name) : b_(b), end_(end), name_(name) {}
  template <class T>
  T get(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::vector<std::uint8_t> take(std::size_t n, const char* what) {
    need(n, what);
    std::vector<std::uint8_t> v(b_.begin() + static_cast<std::ptrdiff_t>(pos_), b_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += n;
    return v;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(name_ + ": at byte " + std::to_string(pos_) + ": " + what);
  }
  [[nodiscard]] std::size_t pos() const { return pos_; }

 private:
  void need(std::size_t n, const char* what) const {
    if (n > end_ - pos_) fail(std::string("truncated while reading ") + what);
  }
  const std::vector<std::uint8_t>& b_;
  std::size_t end_;
  std::size_t pos_ = 0;
  const std::string& name_;
};

void put_sample(Writer& w, bool have, const hal::AxisSample& s) {
  w.put<std::uint8_t>(have ? 1 : 0);
  w.put<std::uint64_t>(s.seq);
  w.put<std::int64_t>(s.t_src_ns);
  w.put<std::uint8_t>(s.channel);
  w.put<std::uint8_t>(s.mask);
  w.put<std::int16_t>(s.tool);
  for (double q : s.q) w.put<double>(q);
}

void get_sample(Reader& r, std::uint32_t version, bool& have, hal::AxisSample& s) {
  have = r.get<std::uint8_t>("channel flag") != 0;
  s.seq = r.get<std::uint64_t>("sample sequence");
  if (version >= 2) s.t_src_ns = r.get<std::int64_t>("sample sender time");
  s.channel = r.get<std::uint8_t>("sample channel");
  s.mask = r.get<std::uint8_t>("sample mask");
  s.tool = r.get<std::int16_t>("sample tool");
  for (double& q : s.q) q = r.get<double>("sample axis value");
}

void fsync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) throw std::runtime_error(path + ": cannot open for fsync: " + std::strerror(errno));
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) throw std::runtime_error(path + ": fsync failed: " + std::strerror(errno));
}

}  // namespace

geom::SolidSpec placeholder_solid_spec() {
  geom::SolidSpec s;
  s.box.min = {0, 0, 0};
  s.box.max = {1, 1, 1};
  s.level_spacing_mm = 1.0;
  s.regions_x = s.regions_y = 1;
  return s;
}

std::uint32_t crc32(const std::uint8_t* data, std::size_t n, std::uint32_t crc) noexcept {
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320U & (0U - (crc & 1U)));
  }
  return ~crc;
}

std::vector<std::uint8_t> encode_snapshot(const SnapshotState& s) {
  Writer w;
  w.bytes(reinterpret_cast<const std::uint8_t*>(kMagic), sizeof kMagic);
  w.put<std::uint32_t>(kFormatVersion);
  w.put<std::uint64_t>(s.generation);
  w.put<std::uint64_t>(s.source_position);
  w.put<std::uint64_t>(s.samples_applied);
  w.put<std::uint64_t>(s.record_offset);
  w.put<double>(s.wall_time_s);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(s.source.size()));
  w.bytes(reinterpret_cast<const std::uint8_t*>(s.source.data()), s.source.size());
  w.put<std::uint32_t>(static_cast<std::uint32_t>(s.record_file.size()));
  w.bytes(reinterpret_cast<const std::uint8_t*>(s.record_file.data()), s.record_file.size());
  w.put<std::uint32_t>(hal::kMaxChannels);
  for (int c = 0; c < hal::kMaxChannels; ++c) put_sample(w, s.have[c], s.last[c]);
  const std::vector<std::uint8_t> levels = geom::to_bytes(s.solid);
  w.put<std::uint64_t>(levels.size());
  w.bytes(levels.data(), levels.size());
  w.put<std::uint32_t>(crc32(w.out.data(), w.out.size()));
  return std::move(w.out);
}

SnapshotState decode_snapshot(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  if (bytes.size() < sizeof kMagic + 4)
    throw std::runtime_error(name + ": at byte " + std::to_string(bytes.size()) + ": truncated (" +
                             std::to_string(bytes.size()) + " bytes, not a complete snapshot)");
  Reader r(bytes, bytes.size() - 4, name);
  for (char c : kMagic)
    if (r.get<char>("magic") != c) r.fail("not a snapshot file (magic \"LBRSNAP1\" expected)");
  std::uint32_t stored = 0;
  std::memcpy(&stored, bytes.data() + bytes.size() - 4, 4);
  if (crc32(bytes.data(), bytes.size() - 4) != stored)
    throw std::runtime_error(name + ": at byte " + std::to_string(bytes.size() - 4) +
                             ": CRC-32 mismatch (truncated or corrupt snapshot)");
  const auto version = r.get<std::uint32_t>("format version");
  if (version != 1 && version != kFormatVersion)
    r.fail("format version 1 or " + std::to_string(kFormatVersion) + " expected, got " + std::to_string(version));
  SnapshotState s;
  s.generation = r.get<std::uint64_t>("generation");
  s.source_position = r.get<std::uint64_t>("source position");
  s.samples_applied = r.get<std::uint64_t>("samples applied");
  s.record_offset = r.get<std::uint64_t>("record offset");
  s.wall_time_s = r.get<double>("wall time");
  const std::vector<std::uint8_t> src = r.take(r.get<std::uint32_t>("source length"), "source spec");
  s.source.assign(src.begin(), src.end());
  if (version >= 2) {
    const std::vector<std::uint8_t> rec = r.take(r.get<std::uint32_t>("record file length"), "record file");
    s.record_file.assign(rec.begin(), rec.end());
  }
  if (r.get<std::uint32_t>("channel count") != hal::kMaxChannels)
    r.fail("channel count " + std::to_string(hal::kMaxChannels) + " expected");
  for (int c = 0; c < hal::kMaxChannels; ++c) get_sample(r, version, s.have[c], s.last[c]);
  const auto n = r.get<std::uint64_t>("level file length");
  if (n != bytes.size() - 4 - r.pos()) r.fail("level file length " + std::to_string(n) + " does not match the file size");
  try {
    s.solid = geom::from_bytes(r.take(static_cast<std::size_t>(n), "level file"));
  } catch (const std::exception& e) {
    r.fail(std::string("embedded level file: ") + e.what());
  }
  return s;
}

void write_file_durably(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(tmp + ": cannot open for writing: " + std::strerror(errno));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string err = std::strerror(errno);
      ::close(fd);
      throw std::runtime_error(tmp + ": write failed: " + err);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const std::string err = std::strerror(errno);
    ::close(fd);
    throw std::runtime_error(tmp + ": fsync failed: " + err);
  }
  ::close(fd);
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error(path + ": rename from " + tmp + " failed: " + std::strerror(errno));
  const std::string dir = std::filesystem::path(path).parent_path().string();
  fsync_path(dir.empty() ? "." : dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);  // the rename itself
}

LoadedSnapshot load_newest_snapshot(const std::string& dir) {
  LoadedSnapshot out;
  for (const char* f : kFiles) {
    const std::string path = (std::filesystem::path(dir) / f).string();
    std::ifstream in(path, std::ios::binary);
    if (!in) continue;
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
      SnapshotState s = decode_snapshot(bytes, path);
      if (!out.state || s.generation > out.state->generation) {
        out.state = std::move(s);
        out.file = path;
      }
    } catch (const std::exception& e) {
      out.problems.emplace_back(e.what());
    }
  }
  return out;
}

SnapshotWriter::SnapshotWriter(std::string dir, std::uint64_t first_generation, AfterWrite after_write)
    : dir_(std::move(dir)), generation_(first_generation), after_write_(std::move(after_write)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw std::runtime_error(dir_ + ": cannot create the snapshot folder: " + ec.message());
  thread_ = std::thread([this] { loop(); });
}

SnapshotWriter::~SnapshotWriter() {
  quit_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

SnapshotState* SnapshotWriter::slot() noexcept {
  return state_.load(std::memory_order_acquire) == kFree ? &slot_ : nullptr;
}

void SnapshotWriter::commit() noexcept { state_.store(kFilled, std::memory_order_release); }

void SnapshotWriter::write(SnapshotState& s) {
  s.generation = generation_++;
  // Generation parity picks the file: the newest never overwrites the one before it.
  const std::string path = (std::filesystem::path(dir_) / kFiles[s.generation % 2]).string();
  try {
    write_file_durably(path, encode_snapshot(s));
    written_.fetch_add(1, std::memory_order_relaxed);
  } catch (const std::exception& e) {
    error_ = e.what();
    failed_.fetch_add(1, std::memory_order_relaxed);
  }
}

void SnapshotWriter::loop() {
  for (;;) {
    if (state_.load(std::memory_order_acquire) == kFilled) {
      write(slot_);
      if (after_write_) after_write_(slot_);
      state_.store(kFree, std::memory_order_release);
      continue;
    }
    if (quit_.load(std::memory_order_acquire)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void SnapshotWriter::write_now(SnapshotState& s) {
  quit_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();  // a pending periodic one first: generations stay in order
  write(s);
  if (failed_.load() > 0 && written_.load() == 0) throw std::runtime_error(error_);
}

std::string SnapshotWriter::last_error() const { return error_; }

}  // namespace lbr::app
