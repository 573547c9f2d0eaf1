#pragma once
// Results passed between ranks as bytes: a plain little packer (both ends are the same program on
// the same kind of machine, so values travel in their native representation), doubles bit for bit
// so that rank 0 writes exactly what the rank that computed them had. One function per structure
// serves both directions (`Writer` and `Reader` have the same `io`), so that a field cannot be
// written and not read. Private to compare: the variants' shares, the sweep's points and
// calibration's load errors go through it.

#include <Eigen/Core>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace msfem::compare::detail {

class Packer {
 public:
  template <typename T>
  std::enable_if_t<std::is_arithmetic_v<T>> put(T value) {
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof value);
  }
  void put(const std::string& s) {
    put(static_cast<long long>(s.size()));
    bytes_ += s;
  }
  template <typename Derived>
  void put(const Eigen::PlainObjectBase<Derived>& m) {
    put(static_cast<long long>(m.rows()));
    put(static_cast<long long>(m.cols()));
    bytes_.append(reinterpret_cast<const char*>(m.data()),
                  sizeof(typename Derived::Scalar) * static_cast<std::size_t>(m.size()));
  }
  template <typename T>
  std::enable_if_t<std::is_enum_v<T>> put(T value) {
    put(static_cast<std::underlying_type_t<T>>(value));
  }
  template <typename T>
  void put(const std::optional<T>& o) {
    put(static_cast<char>(o.has_value()));
    if (o) put(*o);
  }
  template <typename T>
  void put(const std::vector<T>& list) {
    put(static_cast<long long>(list.size()));
    for (const T& item : list)
      put(item);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class Unpacker {
 public:
  explicit Unpacker(const std::string& bytes) : bytes_(bytes) {}
  template <typename T>
  std::enable_if_t<std::is_arithmetic_v<T>> get(T& value) {
    take(&value, sizeof value);
  }
  void get(std::string& s) {
    long long n = 0;
    get(n);
    s.resize(static_cast<std::size_t>(n));
    take(s.data(), s.size());
  }
  template <typename Derived>
  void get(Eigen::PlainObjectBase<Derived>& m) {
    long long rows = 0, cols = 0;
    get(rows);
    get(cols);
    m.resize(rows, cols);
    take(m.data(), sizeof(typename Derived::Scalar) * static_cast<std::size_t>(m.size()));
  }
  template <typename T>
  std::enable_if_t<std::is_enum_v<T>> get(T& value) {
    std::underlying_type_t<T> raw{};
    get(raw);
    value = static_cast<T>(raw);
  }
  template <typename T>
  void get(std::vector<T>& list) {
    long long n = 0;
    get(n);
    if (n < 0 || static_cast<std::size_t>(n) > bytes_.size())
      throw std::runtime_error("a rank's results are garbled");
    list.resize(static_cast<std::size_t>(n));
    for (T& item : list)
      get(item);
  }
  template <typename T>
  void get(std::optional<T>& o) {
    char present = 0;
    get(present);
    o.reset();
    if (!present) return;
    o.emplace();
    get(*o);
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  void take(void* to, std::size_t n) {
    if (n > bytes_.size() - at_) throw std::runtime_error("a rank's variant results are truncated");
    std::memcpy(to, bytes_.data() + at_, n);
    at_ += n;
  }
  const std::string& bytes_;
  std::size_t at_ = 0;
};

struct Writer {
  Packer p;
  template <typename T>
  void io(const T& v) {
    p.put(v);
  }
};
// The structures more than one result carries: a load's errors (run's and calibrate's alike).
template <typename Io, typename M>
void error_metric_fields(Io& io, M& m) {  // ErrorMetrics
  io.io(m.rel_l2_error), io.io(m.rms_error_m), io.io(m.max_error_m);
  io.io(m.mean_error_over_max_disp), io.io(m.vertices);
}

template <typename Io, typename E>
void load_error_fields(Io& io, E& e) {  // LoadErrors
  error_metric_fields(io, e.displacement.all), error_metric_fields(io, e.displacement.contact_zone);
  error_metric_fields(io, e.displacement.far_field);
  io.io(e.tool_force), io.io(e.force_measured), io.io(e.reaction_force_rel_error);
}

struct Reader {
  Unpacker u;
  template <typename T>
  void io(T& v) {
    u.get(v);
  }
};

}  // namespace msfem::compare::detail
