#pragma once
// plots.cpp's one way of running gnuplot, for the writers that draw their own kind of picture.

#include <filesystem>
#include <string>
#include <vector>

namespace msfem::compare::detail {

/// Runs `commands` (which read `data`, written to a scratch file, through the gnuplot variable
/// `data`) on a width x height PNG (SVG where the path ends in .svg or pngcairo is missing),
/// written atomically; returns the path written. std::runtime_error with gnuplot's message on
/// failure. Each of `more_data` is read through `data2`, `data3`, ...
std::filesystem::path render(const std::filesystem::path& requested, const std::string& data,
                             const std::string& commands, int width = 900, int height = 600,
                             const std::vector<std::string>& more_data = {});

/// A gnuplot single-quoted string: literal except that '' stands for '; line breaks become spaces.
std::string quoted(const std::string& text);

/// A number as gnuplot reads it back to the last bit.
std::string number(double value);

}  // namespace msfem::compare::detail
