#include "app/comparison.h"

#include "app/reference_command.h"
#include "renderer/error.h"
#include "renderer/film/film.h"
#include "renderer/film/image_io.h"

#include <cmath>
#include <cstdio>

namespace pdflab {

void check_comparison_options(const ComparisonOptions& o, const std::vector<std::string>& other_outputs) {
  if (o.seconds != 0.0 && !(std::isfinite(o.seconds) && o.seconds > 0.0))
    throw InputError("--seconds must be a positive number of seconds");
  if ((o.seconds > 0) == (o.spp > 0)) throw InputError("give exactly one of --seconds (equal time) and --spp (equal samples)");
  if (o.threads < 0) throw InputError("--threads must be >= 0");
  std::vector<std::string> outputs = {o.csv, o.plot};
  outputs.insert(outputs.end(), other_outputs.begin(), other_outputs.end());
  check_output_path(o.csv);
  for (std::size_t i = 1; i < outputs.size(); ++i)
    if (!outputs[i].empty()) check_output_path(outputs[i]);
  check_distinct_outputs(outputs);
}

ReferenceChoice reference_choice(const ComparisonOptions& o) {
  return {o.reference, o.scene, o.cache_dir, o.width, o.height};
}

Reference comparison_reference(Scene& scene, const ReferenceChoice& choice, const std::vector<Strategy>& strategies,
                               const std::vector<std::uint64_t>& seeds, bool quiet) {
  Reference reference;
  if (choice.option == "auto") {
    if (choice.width) scene.camera.width = choice.width;
    if (choice.height) scene.camera.height = choice.height;
    check_image_size(scene.camera.width, scene.camera.height, "--width/--height");
    scene.prepare();
    reference = resolve_reference(choice.option, scene, choice.scene_file, choice.cache_dir, true, quiet);
  } else {
    if (choice.width || choice.height)
      throw InputError("--width/--height go with --reference auto; a file's size is its own");
    reference = load_reference(choice.option);  // InputError: unreadable, truncated, not finite
    scene.camera.width = reference.width;
    scene.camera.height = reference.height;
    scene.prepare();
  }
  // Decorrelation: no run may repeat the reference's random numbers.
  for (const Strategy& s : strategies)
    for (std::uint64_t seed : seeds)
      if (const std::string shared = shared_random_numbers(reference.info, seed, s); !shared.empty())
        throw InputError("reference '" + reference.path + "': " + shared + "; choose another --seed");
  if (!quiet) note_unknown_seed(reference, seeds);
  if (!quiet && !reference.has_variance())
    std::fprintf(stderr,
                 "note: reference '%s' has no variance file: relmse cannot be corrected for its own noise "
                 "(make one with pdflab reference)\n",
                 printable(reference.path).c_str());
  return reference;
}

}  // namespace pdflab
