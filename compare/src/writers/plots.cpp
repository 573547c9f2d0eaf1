// The report's plots, drawn by gnuplot: each function checks its input, writes a data file (one
// block per series, gnuplot's `index`) and a script into a scratch folder, and runs gnuplot on the
// script with the output aimed at write_file_atomically's temporary. Titles and names go through
// single-quoted gnuplot strings and the noenhanced terminal option, so "three_tier" stays literal.

#include "msfem/compare/writers/plots.hpp"

#include "plot_render.hpp"

#include "msfem/compare/writers/plot_labels.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "msfem/compare/pipeline/atomic_file.hpp"

extern char** environ;  // NOLINT: POSIX's, passed on so gnuplot finds its fonts and locale

namespace msfem::compare {

namespace fs = std::filesystem;

namespace {

// A folder under the system's temporary directory for one gnuplot run, removed with the object.
class ScratchDirectory {
 public:
  ScratchDirectory() {
    std::string pattern = (fs::temp_directory_path() / "msfem-plot-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr)
      throw std::system_error(errno, std::generic_category(), "cannot create " + pattern);
    path_ = pattern;
  }
  ~ScratchDirectory() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

struct GnuplotRun {
  int exit_status = -1;  ///< gnuplot's exit status; 127 if it could not be started
  std::string error_output;
};

// gnuplot ARGS without a shell (no quoting of paths), stdin from /dev/null so that a script never
// waits for input, stdout discarded, stderr kept for the error message.
GnuplotRun run_gnuplot(const std::vector<std::string>& arguments) {
  ScratchDirectory scratch;
  const std::string stderr_file = (scratch.path() / "stderr.txt").string();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, stderr_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0600);
  std::vector<std::string> argv_text{"gnuplot"};
  argv_text.insert(argv_text.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text)
    argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawn_error = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  GnuplotRun run;
  if (spawn_error != 0) {
    run.exit_status = 127;
    run.error_output = "cannot start gnuplot: " + std::string(std::strerror(spawn_error)) +
                       " (install gnuplot-nox)";
    return run;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::system_error(errno, std::generic_category(), "waitpid");
  }
  run.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  run.error_output = read_text(stderr_file);
  return run;
}

bool gnuplot_has_pngcairo() {
  static const bool has = run_gnuplot({"-e", "set terminal pngcairo"}).exit_status == 0;
  return has;
}

}  // namespace

namespace detail {

std::string quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'')
      out += "''";
    else if (c == '\n' || c == '\r' || c == '\t')
      out += ' ';
    else
      out += c;
  }
  return out + "'";
}

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

}  // namespace detail

namespace {

using detail::number;
using detail::quoted;

struct OutputFormat {
  fs::path path;
  std::string terminal;
};

std::string lowercase_extension(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

void require_picture_name(const fs::path& path) {
  const std::string extension = lowercase_extension(path);
  if (extension != ".png" && extension != ".svg")
    throw std::invalid_argument("plot '" + path.string() + "': the name must end in .png or .svg");
}

OutputFormat choose_format(const fs::path& requested, int width, int height) {
  const std::string size = std::to_string(width) + "," + std::to_string(height);
  const std::string svg =
      "set terminal svg size " + size + " noenhanced font 'sans,12' background 'white'";
  if (lowercase_extension(requested) == ".svg") return {requested, svg};
  if (gnuplot_has_pngcairo())
    return {requested, "set terminal pngcairo size " + size + " noenhanced font 'sans,11'"};
  return {fs::path(requested).replace_extension(".svg"), svg};
}

}  // namespace

namespace detail {

fs::path render(const fs::path& requested, const std::string& data, const std::string& commands,
                int width, int height, const std::vector<std::string>& more_data) {
  require_picture_name(requested);
  if (!gnuplot_available())
    throw std::runtime_error("cannot draw '" + requested.string() +
                             "': gnuplot is not installed (Debian: gnuplot-nox)");
  const OutputFormat format = choose_format(requested, width, height);
  ScratchDirectory scratch;
  const fs::path data_file = scratch.path() / "data.dat";
  const fs::path script_file = scratch.path() / "plot.gp";
  write_text_atomically(data_file, data);
  std::string more_names;
  for (std::size_t i = 0; i < more_data.size(); ++i) {
    const fs::path file = scratch.path() / ("data" + std::to_string(i + 2) + ".dat");
    write_text_atomically(file, more_data[i]);
    more_names += "data" + std::to_string(i + 2) + " = " + quoted(file.string()) + "\n";
  }
  write_file_atomically(format.path, [&](const fs::path& temporary) {
    std::ostringstream script;
    script << format.terminal << "\n"
           << "set output " << quoted(temporary.string()) << "\n"
           << "data = " << quoted(data_file.string()) << "\n"
           << more_names << "set grid\nset key below\n"
           << commands << "unset output\n";
    write_text_atomically(script_file, script.str());
    const GnuplotRun run = run_gnuplot({script_file.string()});
    if (run.exit_status != 0)
      throw std::runtime_error("gnuplot failed (exit " + std::to_string(run.exit_status) +
                               "): " + run.error_output);
    std::error_code error;
    if (fs::file_size(temporary, error) == 0 || error)
      throw std::runtime_error("gnuplot wrote nothing: " + run.error_output);
  });
  return format.path;
}

}  // namespace detail

namespace {

using detail::render;

std::string labels(const std::string& title, const std::string& xlabel, const std::string& ylabel) {
  return "set title " + quoted(title) + "\nset xlabel " + quoted(xlabel) + "\nset ylabel " +
         quoted(ylabel) + "\n";
}

void require_plottable(const std::string& series, const std::vector<double>& values,
                       const char* axis, bool log_axis) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]))
      throw std::invalid_argument("series '" + series + "': " + axis + "[" + std::to_string(i) +
                                  "] is not finite");
    if (log_axis && !(values[i] > 0))
      throw std::invalid_argument("series '" + series + "': " + axis + "[" + std::to_string(i) +
                                  "] = " + number(values[i]) + " cannot go on a log axis");
  }
}

}  // namespace

std::string variant_colour(std::size_t i) {
  // Okabe and Ito's colour-blind-safe set, then Tableau's.
  static const char* const colours[] = {"#0072b2", "#e69f00", "#009e73", "#d55e00", "#cc79a7",
                                        "#56b4e9", "#f0e442", "#8c564b", "#7f7f7f", "#bcbd22"};
  return colours[i % (sizeof colours / sizeof *colours)];
}

bool gnuplot_available() {
  static const bool available = run_gnuplot({"--version"}).exit_status == 0;
  return available;
}

fs::path histogram(const fs::path& path, const std::string& title, const std::string& xlabel,
                   const std::vector<std::pair<std::string, Eigen::VectorXd>>& series, int bins,
                   const std::vector<std::string>& colours) {
  if (series.empty()) throw std::invalid_argument("histogram '" + title + "': no series");
  if (bins < 1) throw std::invalid_argument("histogram '" + title + "': bins must be >= 1");
  double low = INFINITY, high = -INFINITY;
  for (const auto& [name, values] : series) {
    if (values.size() == 0) throw std::invalid_argument("series '" + name + "' is empty");
    require_plottable(name, std::vector<double>(values.data(), values.data() + values.size()),
                      "value", false);
    low = std::min(low, values.minCoeff());
    high = std::max(high, values.maxCoeff());
  }
  if (high == low) {  // one value everywhere (e.g. no error at all): a bin around it
    const double half = low != 0 ? std::abs(low) * 0.5 : 1.0;
    low -= half;
    high += half;
  }
  const double width = (high - low) / bins;
  // Common bins for every series; each drawn as a closed step outline from 0 up and back to 0.
  std::ostringstream data;
  for (const auto& [name, values] : series) {
    std::vector<int> counts(static_cast<std::size_t>(bins), 0);
    for (double v : values)
      ++counts[static_cast<std::size_t>(
          std::clamp(static_cast<int>((v - low) / width), 0, bins - 1))];
    data << number(low) << " 0\n";
    for (int b = 0; b < bins; ++b)
      data << number(low + b * width) << ' ' << counts[b] << '\n';
    data << number(high) << ' ' << counts.back() << '\n' << number(high) << " 0\n\n\n";
  }
  std::ostringstream commands;
  commands << labels(title, xlabel, "count") << "set yrange [0:*]\nplot ";
  for (std::size_t i = 0; i < series.size(); ++i)
    commands << (i ? ", \\\n     " : "") << "data index " << i << " using 1:2 with steps lw 2"
             << (i < colours.size() ? " lc rgb " + quoted(colours[i]) : "") << " title "
             << quoted(series[i].first);
  commands << "\n";
  return render(path, data.str(), commands.str());
}

fs::path xy_lines(const fs::path& path, const std::string& title, const std::string& xlabel,
                  const std::string& ylabel, const std::vector<Series>& series, bool logx,
                  bool logy) {
  if (series.empty()) throw std::invalid_argument("plot '" + title + "': no series");
  std::ostringstream data;
  for (const Series& s : series) {
    if (s.x.empty()) throw std::invalid_argument("series '" + s.name + "' is empty");
    if (s.x.size() != s.y.size())
      throw std::invalid_argument("series '" + s.name + "' has " + std::to_string(s.x.size()) +
                                  " x values and " + std::to_string(s.y.size()) + " y values");
    require_plottable(s.name, s.x, "x", logx);
    require_plottable(s.name, s.y, "y", logy);
    for (std::size_t i = 0; i < s.x.size(); ++i)
      data << number(s.x[i]) << ' ' << number(s.y[i]) << '\n';
    data << "\n\n";
  }
  std::ostringstream commands;
  commands << labels(title, xlabel, ylabel) << (logx ? "set logscale x\n" : "")
           << (logy ? "set logscale y\n" : "") << "plot ";
  for (std::size_t i = 0; i < series.size(); ++i)
    commands << (i ? ", \\\n     " : "") << "data index " << i
             << " using 1:2 with linespoints lw 2 pt 7 ps 0.7"
             << (series[i].colour.empty() ? "" : " lc rgb " + quoted(series[i].colour)) << " title "
             << quoted(series[i].name);
  commands << "\n";
  return render(path, data.str(), commands.str());
}

namespace {

// The points no other point beats on both speed and accuracy, in increasing speed.
std::vector<ParetoPoint> pareto_front(std::vector<ParetoPoint> points) {
  std::sort(points.begin(), points.end(), [](const ParetoPoint& a, const ParetoPoint& b) {
    return a.realtime_factor != b.realtime_factor ? a.realtime_factor > b.realtime_factor
                                                  : a.rel_error < b.rel_error;
  });
  std::vector<ParetoPoint> front;
  for (const ParetoPoint& p : points)
    if (front.empty() || p.rel_error < front.back().rel_error) front.push_back(p);
  std::reverse(front.begin(), front.end());
  return front;
}

// The distinct values of a field of the points, in first-seen order.
template <typename Field>
std::vector<std::string> groups_of(const std::vector<ParetoPoint>& points, Field field) {
  std::vector<std::string> groups;
  for (const ParetoPoint& p : points)
    if (std::find(groups.begin(), groups.end(), p.*field) == groups.end())
      groups.push_back(p.*field);
  return groups;
}

// The plot area at fixed screen fractions, so that the labels' boxes (pixels) are known before
// gnuplot draws: 900 x 600 pixels, the legend above the area.
constexpr double kAreaLeft = 0.10, kAreaRight = 0.97, kAreaBottom = 0.10, kAreaTop = 0.76;
std::string pareto_margins() {
  return "set lmargin at screen " + number(kAreaLeft) + "\nset rmargin at screen " +
         number(kAreaRight) + "\nset bmargin at screen " + number(kAreaBottom) +
         "\nset tmargin at screen " + number(kAreaTop) + "\n";
}

// The log-log ranges shown: x from, x to, y from, y to.
struct LogRanges {
  double x0, x1, y0, y1;
};

// gnuplot labels for the front's points where place_labels found room (each with a leader line
// where it had to move off its point's row); a label with no room is left out, its point stays.
std::string front_labels(const std::vector<ParetoPoint>& front,
                         const std::vector<ParetoPoint>& points, const LogRanges& r) {
  LabelMetrics metrics;
  metrics.area_width_px = (kAreaRight - kAreaLeft) * 900.0;
  metrics.area_height_px = (kAreaTop - kAreaBottom) * 600.0;
  const auto fraction = [](double v, double from, double to) {
    return std::log(v / from) / std::log(to / from);
  };
  const auto pixels = [&](const ParetoPoint& p) {
    return std::make_pair(fraction(p.realtime_factor, r.x0, r.x1) * metrics.area_width_px,
                          fraction(p.rel_error, r.y0, r.y1) * metrics.area_height_px);
  };
  std::vector<std::pair<double, double>> at, others;
  std::vector<std::string> texts;
  for (const ParetoPoint& p : front) {
    at.push_back(pixels(p));
    texts.push_back(p.label);
  }
  for (const ParetoPoint& p : points)
    others.push_back(pixels(p));
  std::ostringstream out;
  const std::vector<PlacedLabel> placed = place_labels(at, texts, metrics, others);
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const PlacedLabel& l = placed[i];
    if (!l.placed) continue;
    const double gx = l.x_px / metrics.area_width_px, gy = l.y_px / metrics.area_height_px;
    out << "set label " << quoted(texts[i]) << " at graph " << number(gx) << ", " << number(gy)
        << (l.right_of_point ? " left" : " right") << " font ',9' front\n";
    if (l.displaced)
      out << "set arrow from first " << number(front[i].realtime_factor) << ", first "
          << number(front[i].rel_error) << " to graph " << number(gx) << ", " << number(gy)
          << " nohead lw 0.5 lc 'gray50'\n";
  }
  return out.str();
}

}  // namespace

fs::path pareto(const fs::path& path, const std::string& title,
                const std::vector<ParetoPoint>& points) {
  if (points.empty()) throw std::invalid_argument("pareto plot '" + title + "': no points");
  const std::vector<std::string> colours = groups_of(points, &ParetoPoint::colour_group);
  const std::vector<std::string> markers = groups_of(points, &ParetoPoint::marker_group);
  static const int marker_types[] = {7, 5, 9, 11, 13, 15, 4, 6};  // filled circle, square, ...
  // The x range always shows real time, so every point reads against it.
  double x_low = 1.0, x_high = 1.0;
  std::ostringstream data;
  for (const std::string& group : colours) {  // data block per colour group
    for (const ParetoPoint& p : points) {
      if (p.colour_group != group) continue;
      require_plottable(p.label, {p.realtime_factor}, "realtime_factor", true);
      require_plottable(p.label, {p.rel_error}, "rel_error", true);
      x_low = std::min(x_low, p.realtime_factor);
      x_high = std::max(x_high, p.realtime_factor);
      const auto m = std::find(markers.begin(), markers.end(), p.marker_group) - markers.begin();
      data << number(p.realtime_factor) << ' ' << number(p.rel_error) << ' ' << marker_types[m % 8]
           << ' ' << (p.ringed ? 1 : 0) << '\n';
    }
    data << "\n\n";
  }
  const std::vector<ParetoPoint> front_points = pareto_front(points);
  for (const ParetoPoint& p : front_points)
    data << number(p.realtime_factor) << ' ' << number(p.rel_error) << '\n';
  const std::size_t front = colours.size();
  const auto [lowest, highest] = std::minmax_element(
      points.begin(), points.end(),
      [](const ParetoPoint& a, const ParetoPoint& b) { return a.rel_error < b.rel_error; });
  const double y_low = std::pow(10.0, std::floor(std::log10(lowest->rel_error)));
  const double y_high =
      std::max(std::pow(10.0, std::ceil(std::log10(highest->rel_error))), 10 * y_low);
  std::ostringstream commands;
  commands << labels(title, "real-time factor (simulated s per wall s)", "relative error")
           << "set logscale xy\nset key outside right top\n"
           << "set xrange [" << number(x_low / 2) << ":" << number(x_high * 4) << "]\n"
           << "set yrange [" << number(y_low) << ":" << number(y_high) << "]\n"
           << pareto_margins()
           << front_labels(front_points, points, {x_low / 2, x_high * 4, y_low, y_high})
           << "set arrow from 1, graph 0 to 1, graph 1 nohead dt 2 lw 1.5 lc 'gray30'\n"
           << "set label 'real time' at 1, graph 0.96 offset char 0.5,0 left tc 'gray30'\n"
           << "plot data index " << front
           << " using 1:2 with lines dt 2 lw 2 lc 'gray40' title 'Pareto front'";
  // The legend: a filled square per colour, then a black marker per marker group.
  for (std::size_t c = 0; c < colours.size(); ++c)
    commands << ", \\\n     data index " << c << " using 1:2:3 with points pt variable ps 1.3 lc "
             << c + 1 << " notitle, \\\n     NaN with points pt 5 ps 1.3 lc " << c + 1 << " title "
             << quoted(colours[c].empty() ? "configurations" : colours[c]);
  for (std::size_t m = 0; m < markers.size() && markers.size() > 1; ++m)
    commands << ", \\\n     NaN with points pt " << marker_types[m % 8]
             << " ps 1.3 lc 'black' title " << quoted(markers[m]);
  if (std::any_of(points.begin(), points.end(), [](const ParetoPoint& p) { return p.ringed; }))
    for (std::size_t c = 0; c < colours.size(); ++c)
      commands << ", \\\n     data index " << c
               << " using 1:($4 > 0 ? $2 : NaN) with points pt 6 ps 2.6 lw 1.5 lc 'black' "
               << (c == 0 ? "title '1 kHz in real time'" : "notitle");
  commands << "\n";
  return render(path, data.str(), commands.str());
}

}  // namespace msfem::compare
