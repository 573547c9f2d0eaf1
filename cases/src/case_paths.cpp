// Every path a case names is relative to the case file (when written relative), so that a case
// runs from any folder; a path that must exist is checked here, before anything is built.
#include "case_paths.hpp"

#include "msfem/cases/errors.hpp"
#include "msfem/cases/network_file.hpp"
#include "msfem/cases/surface_from_image.hpp"
#include "msfem/cases/surface_generators.hpp"

namespace msfem::cases {

void resolve_paths(CaseParameters& c) {
  for (auto& network : c.mass_spring.networks) {
    if (network.file.is_relative())
      network.file = (c.file.parent_path() / network.file).lexically_normal();
    if (!std::filesystem::is_regular_file(network.file))
      throw InputError(c.file.string() + ": mass spring/networks: " + network.name + "=" +
                       network.file.string() + ": no such file");
  }
  for (auto& result : c.mass_spring.results)
    for (auto& file : result.files) {
      if (file.is_relative()) file = (c.file.parent_path() / file).lexically_normal();
      if (!std::filesystem::is_regular_file(file))
        throw InputError(c.file.string() + ": mass spring/results: " + result.name + "=" +
                         file.string() + ": no such file");
    }
  // A relative surface path is relative to the case file, so cases run from any folder.
  if (is_image_source(c.geometry.source)) {
    try {
      c.geometry.source = image_source_relative_to(c.geometry.source, c.file.parent_path());
    } catch (const InputError& e) {
      throw InputError(c.file.string() + ": " + e.what());
    }
  } else if (is_network_source(c.geometry.source)) {
    const std::filesystem::path network = network_source_file(c.geometry.source);
    if (network.is_relative())
      c.geometry.source = "network:" + (c.file.parent_path() / network).lexically_normal().string();
  } else if (!is_surface_generator(c.geometry.source)) {
    const std::filesystem::path p(c.geometry.source);
    if (p.is_relative()) c.geometry.source = (c.file.parent_path() / p).lexically_normal().string();
  }
  if (const std::filesystem::path image(c.material.youngs_modulus_image);
      !image.empty() && image.is_relative())
    c.material.youngs_modulus_image = (c.file.parent_path() / image).lexically_normal().string();
}

}  // namespace msfem::cases
