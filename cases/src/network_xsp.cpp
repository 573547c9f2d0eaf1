// SOFA's Xsp spring files ("Xsp 3.0" .xs3, "Xsp 4.0" .xs4), read as SOFA's
// sofa::helper::io::XspLoader reads them: whitespace-separated tokens (a record may span lines), a
// keyword per record, '#' at a keyword's place comments out the rest of its line.
//
//   numm N                                       masses announced (at most once)
//   nums N                                       springs announced (at most once)
//   mass index location x y z vx vy vz m elastic  a mass, numbered by its place among the masses;
//                                                 m < 0 marks it fixed, with mass |m|
//   lspg index i j ks kd l0 [rx ry rz]           a spring between masses i and j (from 1); l0 = -1:
//                                                 the current length, and ks, kd per unit length
//   grav gx gy gz,  visc v
//
// Version 4.0 adds a rest vector (rx ry rz) to each spring, which only SOFA's
// VectorSpringForceField uses; SpringForceField, like msfem, reads central springs and ignores it.
// A mass's index, location, velocity and "elastic" value are read and checked to be numbers but
// used by no SOFA component that builds a spring network, nor by msfem. `step` and `frce`, which
// XspLoader skips, are refused: a file that sets a time step or a force means something msfem
// cannot honour, and its author should know that neither SOFA nor msfem applies it.

#include <cctype>
#include <cfloat>
#include <cmath>

#include "network_detail.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

struct Token {
  std::string_view text;
  std::size_t pos = 0, line = 0;
};

struct SpringTokens {
  Token ks, kd;
  bool per_length = false;  ///< l0 was -1: the file's ks and kd are per unit length
  double length = 0;
};

struct XspFile {
  ReadNetwork read;
  std::vector<SpringTokens> springs;
};

class XspReader {
 public:
  XspReader(const fs::path& file, std::string_view data) : file_(file), data_(data) {}

  bool next(Token& token) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) {
      if (data_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ == data_.size()) return false;
    const std::size_t begin = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_])))
      ++pos_;
    token = {data_.substr(begin, pos_ - begin), begin, line_};
    return true;
  }
  void skip_line() {
    while (pos_ < data_.size() && data_[pos_] != '\n')
      ++pos_;
  }
  Token field(const Token& keyword, const char* form) {
    Token token;
    if (!next(token))
      fail_at_line(file_, keyword.line,
                   "the file ends inside " + detail::quoted(keyword.text) + " (expected '" + form +
                       "'; truncated?)");
    return token;
  }
  double number(const Token& keyword, const char* form) {
    const Token token = field(keyword, form);
    double value;
    if (!parse_double(token.text, value))
      fail_at_line(file_, token.line,
                   detail::quoted(token.text) + " is not a number (expected '" + form + "')");
    return value;
  }
  long long integer(const Token& keyword, const char* form) {
    const Token token = field(keyword, form);
    long long value;
    if (!parse_integer(token.text, value))
      fail_at_line(file_, token.line,
                   detail::quoted(token.text) + " is not an integer (expected '" + form + "')");
    return value;
  }

 private:
  const fs::path& file_;
  std::string_view data_;
  std::size_t pos_ = 0, line_ = 1;
};

constexpr const char* mass_form = "mass index location x y z vx vy vz mass elastic";
constexpr const char* spring3_form = "lspg index mass1 mass2 ks kd rest_length";
constexpr const char* spring4_form = "lspg index mass1 mass2 ks kd rest_length rx ry rz";

void parse_xsp(const fs::path& file, std::string_view data, XspFile& out) {
  XspReader in(file, data);
  Token token;
  if (!in.next(token) || token.text != "Xsp")
    fail(file, "not an Xsp file: it does not start with 'Xsp'");
  const Token header = token;
  const double version = in.number(header, "Xsp 3.0");
  const bool version4 = std::abs(static_cast<float>(version) - 4.0f) <= FLT_EPSILON;
  if (!version4 && std::abs(static_cast<float>(version) - 3.0f) > FLT_EPSILON)
    fail_at_line(file, header.line,
                 "Xsp version " + number_text(version) + " is not one SOFA reads (3.0, 4.0)");

  std::vector<double> xyz, masses;
  std::vector<bool> fixed;
  std::vector<long long> ends;
  std::vector<double> ks, kd, rest;
  NetworkFile& net = out.read.network;
  NetworkOrigin& origin = out.read.origin;
  origin.by_line = true;
  long long announced_masses = -1, announced_springs = -1;
  while (in.next(token)) {
    const std::string_view keyword = token.text;
    if (keyword[0] == '#') {
      in.skip_line();
    } else if (keyword == "numm" || keyword == "nums") {
      long long& announced = keyword == "numm" ? announced_masses : announced_springs;
      if (announced >= 0)
        fail_at_line(file, token.line,
                     "a second " + detail::quoted(keyword) + " (SOFA's XspLoader refuses it too)");
      announced = in.integer(token, keyword == "numm" ? "numm count" : "nums count");
      if (announced < 0) fail_at_line(file, token.line, "a negative count");
    } else if (keyword == "mass") {
      in.integer(token, mass_form);
      const Token location = in.field(token, mass_form);
      if (location.text.size() != 1)
        fail_at_line(file, location.line,
                     "mass location " + detail::quoted(location.text) +
                         " is not one character (SOFA reads 's' as a surface point)");
      for (int k = 0; k < 3; ++k)
        xyz.push_back(in.number(token, mass_form));
      for (int k = 0; k < 3; ++k)
        in.number(token, mass_form);  // velocity
      const double mass = in.number(token, mass_form);
      in.number(token, mass_form);  // elastic
      masses.push_back(mass < 0 ? -mass : mass);
      fixed.push_back(mass < 0);
      origin.point.push_back(static_cast<long long>(token.line));
    } else if (keyword == "lspg") {
      const char* form = version4 ? spring4_form : spring3_form;
      in.integer(token, form);
      const std::string label = "spring " + std::to_string(ks.size() + 1);
      for (int k = 0; k < 2; ++k) {
        const long long id = in.integer(token, form);
        if (id < 1 || id > static_cast<long long>(masses.size()))
          fail_at_line(file, token.line,
                       label + ": mass " + std::to_string(id) + " out of range 1.." +
                           std::to_string(masses.size()) +
                           " (a spring's masses come before it; they count from 1)");
        ends.push_back(id - 1);
      }
      SpringTokens tokens;
      tokens.ks = in.field(token, form);
      tokens.kd = in.field(token, form);
      double k_value, d_value;
      if (!parse_double(tokens.ks.text, k_value) || !parse_double(tokens.kd.text, d_value))
        fail_at_line(file, token.line, label + ": ks and kd must be numbers ('" + form + "')");
      double length = in.number(token, form);
      if (version4)
        for (int k = 0; k < 3; ++k)
          in.number(token, form);  // rest vector
      // XspLoader's rule: -1 (to double precision) means the current length, and then ks and kd
      // are per unit length.
      if (std::abs(length + 1.0) <= DBL_EPSILON) {
        const std::size_t a = static_cast<std::size_t>(ends[ends.size() - 2]);
        const std::size_t b = static_cast<std::size_t>(ends.back());
        const Eigen::Vector3d d(xyz[3 * a] - xyz[3 * b], xyz[3 * a + 1] - xyz[3 * b + 1],
                                xyz[3 * a + 2] - xyz[3 * b + 2]);
        length = d.norm();
        k_value /= length;
        d_value /= length;
        tokens.per_length = true;
        tokens.length = length;
      }
      ks.push_back(k_value);
      kd.push_back(d_value);
      rest.push_back(length);
      out.springs.push_back(tokens);
      origin.spring.push_back(static_cast<long long>(token.line));
    } else if (keyword == "grav") {
      for (int k = 0; k < 3; ++k)
        net.gravity(k) = in.number(token, "grav gx gy gz");
    } else if (keyword == "visc") {
      net.viscosity = in.number(token, "visc value");
    } else if (keyword == "step" || keyword == "frce") {
      fail_at_line(file, token.line,
                   detail::quoted(keyword) +
                       (keyword == "step" ? " (a time step) is a simulation setting"
                                          : " (a force on a mass) is a load") +
                       " msfem does not take from a network file, and SOFA's XspLoader skips it; "
                       "remove the line");
    } else {
      fail_at_line(
          file, token.line,
          "unknown Xsp keyword " + detail::quoted(keyword) + " (SOFA's XspLoader refuses it too)");
    }
  }
  if (announced_masses >= 0 && announced_masses != static_cast<long long>(masses.size()))
    fail(file, "numm announces " + std::to_string(announced_masses) + " masses, the file has " +
                   std::to_string(masses.size()) + " (truncated?)");
  if (announced_springs >= 0 && announced_springs != static_cast<long long>(ks.size()))
    fail(file, "nums announces " + std::to_string(announced_springs) + " springs, the file has " +
                   std::to_string(ks.size()) + " (truncated?)");
  if (ks.empty()) fail(file, "no springs: the file has no 'lspg' lines");

  const auto n = static_cast<Eigen::Index>(masses.size());
  const auto m = static_cast<Eigen::Index>(ks.size());
  net.points =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(xyz.data(), n, 3);
  net.mass = Eigen::Map<const Eigen::VectorXd>(masses.data(), n);
  net.fixed = fixed;
  net.springs.resize(m, 2);
  for (Eigen::Index s = 0; s < m; ++s)
    for (int k = 0; k < 2; ++k)
      net.springs(s, k) = static_cast<int>(ends[static_cast<std::size_t>(2 * s + k)]);
  net.stiffness = Eigen::Map<const Eigen::VectorXd>(ks.data(), m);
  net.damping = Eigen::Map<const Eigen::VectorXd>(kd.data(), m);
  net.rest_length = Eigen::Map<const Eigen::VectorXd>(rest.data(), m);
  net.spring_group = Eigen::VectorXi::Zero(m);
  net.group_names = {"springs"};
}

}  // namespace

ReadNetwork read_xsp(const fs::path& file, std::string_view bytes) {
  XspFile xsp;
  parse_xsp(file, bytes, xsp);
  return std::move(xsp.read);
}

void write_xsp(const fs::path& file, std::string& out, const NetworkFile& net) {
  if (net.tetrahedra.rows() + net.wedges.rows() > 0)
    fail(file, "Xsp has no volume elements: " + std::to_string(net.tetrahedra.rows()) +
                   " tetrahedra and " + std::to_string(net.wedges.rows()) +
                   " wedges and their bulk modulus would be lost (write .vtu)");
  if (net.anchor_stiffness)
    fail(file, "Xsp has no anchors: the points' anchor springs would be lost (write .vtu)");
  if (!net.mass)
    fail(file, "Xsp gives every point a mass, and this network has none (set its masses)");
  std::vector<bool> surface(static_cast<std::size_t>(net.points.rows()), false);
  for (Eigen::Index t = 0; t < net.triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      surface[static_cast<std::size_t>(net.triangles(t, k))] = true;
  out += "Xsp 3.0\n";
  out += "numm " + std::to_string(net.points.rows()) + "\n";
  out += "nums " + std::to_string(net.springs.rows()) + "\n";
  if (!net.gravity.isZero()) {
    out += "grav";
    for (int k = 0; k < 3; ++k)
      out += " " + number_text(net.gravity(k));
    out += "\n";
  }
  if (net.viscosity) out += "visc " + number_text(*net.viscosity) + "\n";
  for (Eigen::Index p = 0; p < net.points.rows(); ++p) {
    const bool fixed = net.fixed && (*net.fixed)[static_cast<std::size_t>(p)];
    out += "mass " + std::to_string(p + 1) + (surface[static_cast<std::size_t>(p)] ? " s" : " i");
    for (int k = 0; k < 3; ++k)
      out += " " + number_text(net.points(p, k));
    out += " 0 0 0 " + number_text(fixed ? -(*net.mass)(p) : (*net.mass)(p)) + " 0\n";
  }
  for (Eigen::Index s = 0; s < net.springs.rows(); ++s) {
    const int a = net.springs(s, 0), b = net.springs(s, 1);
    // Always the rest length itself: -1 would make SOFA divide ks by it, which does not round trip.
    const double length =
        net.rest_length ? (*net.rest_length)(s) : (net.points.row(a) - net.points.row(b)).norm();
    out += "lspg " + std::to_string(s + 1) + " " + std::to_string(a + 1) + " " +
           std::to_string(b + 1) + " " + number_text(net.stiffness(s)) + " " +
           number_text(net.damping ? (*net.damping)(s) : 0.0) + " " + number_text(length) + "\n";
  }
}

std::string xsp_with_coefficients(const fs::path& file, std::string_view bytes,
                                  const Eigen::VectorXd& stiffness,
                                  const std::optional<Eigen::VectorXd>& damping) {
  XspFile xsp;
  parse_xsp(file, bytes, xsp);
  std::string out(bytes);
  // Back to front, so that earlier positions stay valid.
  for (std::size_t s = xsp.springs.size(); s-- > 0;) {
    const SpringTokens& spring = xsp.springs[s];
    const double scale = spring.per_length ? spring.length : 1.0;
    if (damping)
      out.replace(spring.kd.pos, spring.kd.text.size(),
                  number_text((*damping)(static_cast<Eigen::Index>(s)) * scale));
    out.replace(spring.ks.pos, spring.ks.text.size(),
                number_text(stiffness(static_cast<Eigen::Index>(s)) * scale));
  }
  return out;
}

}  // namespace msfem::cases::detail
