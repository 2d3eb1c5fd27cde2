// pvs generate {city,grass,spheres}: writes the procedural test scenes of vislib/scene/generate.h
// (.glb for city and grass, the sphere text format for spheres).
#include <chrono>
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "cli/options.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/generate.h"
#include "vislib/scene/write_gltf.h"
#include "vislib/scene/write_spheres.h"

namespace pvs_cli {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Prints "pvs: <what> N%" to stderr at most every 2 s, once the work has taken more than 2 s.
vislib::GenerateProgress progress_printer(const std::string& what, Clock::time_point t0) {
  auto last = std::make_shared<double>(0.0);
  return [what, t0, last](double fraction) {
    double t = seconds_since(t0);
    if (t < 2 || t - *last < 2 || !show_progress()) return;
    *last = t;
    std::fprintf(stderr, "pvs: %s %3.0f%% (%.1f s)\n", what.c_str(), 100 * fraction, t);
  };
}

void check_extension(const std::string& path, const std::string& ext, const std::string& kind) {
  if (vislib::file_extension(path) != ext) {
    std::fprintf(stderr, "pvs: error: -o %s: %s scenes are written as %s files\n", path.c_str(),
                 kind.c_str(), ext.c_str());
    throw Exit{2};
  }
}

void write_and_report(const std::string& kind, const vislib::Scene& scene, const std::string& path,
                      Clock::time_point t0) {
  double gen = seconds_since(t0);
  if (gen > 2 && show_progress())
    std::fprintf(stderr, "pvs: generated in %.1f s, writing %s\n", gen, path.c_str());
  std::string bytes = vislib::with_memory_stage("encoding " + path, [&] {
    return vislib::file_extension(path) == ".glb" ? vislib::scene_to_glb(scene)
                                                  : vislib::spheres_to_text(scene);
  });
  vislib::write_file_atomic(path, bytes);
  if (show_progress())  // a summary: -q prints errors only
    std::printf(
        "%s: %zu triangles, %zu spheres, %zu objects, %zu states, %zu bytes written to %s "
        "in %.2f s\n",
        kind.c_str(), scene.triangle_count(), scene.sphere_count(), scene.objects.size(),
        scene.state_count(), bytes.size(), path.c_str(), seconds_since(t0));
}

void add_generate(CLI::App& app) {
  auto* gen =
      app.add_subcommand("generate", "Generate a procedural test scene (city, grass, spheres)");
  gen->require_subcommand(1);

  // city
  {
    auto o = std::make_shared<vislib::CityOptions>();
    auto out = std::make_shared<std::string>();
    auto blocks = std::make_shared<std::string>();
    auto heights = std::make_shared<std::string>();
    auto* c =
        gen->add_subcommand("city", "A grid of streets and blocks lined with buildings (.glb)");
    c->add_option("-o,--output", *out, "Output file (.glb)")->required();
    c->add_option("--seed", o->seed, "Random seed")->capture_default_str();
    c->add_option("--blocks", *blocks, "Blocks along x and z, as X,Z (default 6,6)");
    c->add_option("--block-size", o->block_size, "Side of a block (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--street-width", o->street_width, "Street width (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--lots", o->lots_per_side, "Buildings per block side")
        ->capture_default_str()
        ->check(in_range(1, 100));
    c->add_option("--heights", *heights, "Building heights MIN,MAX (m) (default 8,60)");
    c->add_option("--panel", o->panel_size, "Facade panel size (m); 0 = one quad per wall")
        ->capture_default_str()
        ->check(non_negative());
    c->add_option("--target-triangles", o->target_triangles,
                  "Pick the facade detail (and, without --blocks, the grid) for about this many "
                  "triangles");
    c->callback([o, out, blocks, heights] {
      check_extension(*out, ".glb", "city");
      check_output_file(*out, "--output");
      if (!blocks->empty()) {
        auto b = parse_doubles(*blocks, "--blocks", 2);
        if (b[0] < 1 || b[1] < 1 || b[0] != int(b[0]) || b[1] != int(b[1]))
          throw CLI::ValidationError("--blocks", "expected two positive integers X,Z");
        o->blocks_x = int(b[0]);
        o->blocks_z = int(b[1]);
      } else {
        o->auto_blocks = o->target_triangles > 0;
      }
      if (!heights->empty()) {
        auto h = parse_doubles(*heights, "--heights", 2);
        if (!(h[0] > 0 && h[0] <= h[1]))
          throw CLI::ValidationError("--heights", "expected 0 < MIN <= MAX");
        o->min_height = h[0];
        o->max_height = h[1];
      }
      auto t0 = Clock::now();
      o->progress = progress_printer("generating city", t0);
      write_and_report("city",
                       vislib::with_memory_stage("generating the city scene",
                                                 [&] { return vislib::generate_city(*o); }),
                       *out, t0);
    });
  }

  // grass
  {
    auto o = std::make_shared<vislib::GrassOptions>();
    auto out = std::make_shared<std::string>();
    auto* c =
        gen->add_subcommand("grass", "A rolling terrain covered with wind-swept grass (.glb)");
    c->add_option("-o,--output", *out, "Output file (.glb)")->required();
    c->add_option("--seed", o->seed, "Random seed")->capture_default_str();
    c->add_option("--size", o->size, "Side of the square field (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--density", o->density, "Blades per square meter")
        ->capture_default_str()
        ->check(non_negative());
    c->add_option("--target-triangles", o->target_triangles,
                  "Pick the blade count for this many triangles (overrides --density)");
    c->add_option("--blade-triangles", o->blade_triangles, "Triangles per blade")
        ->capture_default_str()
        ->check(in_range(2, 5));
    c->add_option("--blade-height", o->blade_height, "Mean blade height (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--blade-width", o->blade_width, "Mean blade base width (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--patch-size", o->patch_size, "Side of the square patch per object (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--terrain-cell", o->terrain_cell, "Terrain grid spacing (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--terrain-amplitude", o->terrain_amplitude, "Hill height (m)")
        ->capture_default_str()
        ->check(non_negative());
    c->add_option("--states", o->states, "Key states of the wind animation")
        ->capture_default_str()
        ->check(in_range(1, 1000));
    c->add_option("--wind", o->wind_amplitude, "Gust bend angle at the tip (radians)")
        ->capture_default_str()
        ->check(in_range(0.0, 1.4));
    c->add_option("--wavelength", o->wind_wavelength, "Gust wavelength (m)")
        ->capture_default_str()
        ->check(positive());
    c->callback([o, out] {
      check_extension(*out, ".glb", "grass");
      check_output_file(*out, "--output");
      auto t0 = Clock::now();
      o->progress = progress_printer("generating grass", t0);
      write_and_report("grass",
                       vislib::with_memory_stage("generating the grass scene",
                                                 [&] { return vislib::generate_grass(*o); }),
                       *out, t0);
    });
  }

  // spheres
  {
    auto o = std::make_shared<vislib::SphereOptions>();
    auto out = std::make_shared<std::string>();
    auto* c = gen->add_subcommand("spheres", "Bouncing spheres (.spheres text format)");
    c->add_option("-o,--output", *out, "Output file (.spheres)")->required();
    c->add_option("--seed", o->seed, "Random seed")->capture_default_str();
    c->add_option("--count", o->count, "Number of spheres")
        ->capture_default_str()
        ->check(non_negative());
    c->add_option("--radius", o->radius, "Sphere radius (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--area", o->area, "Side of the square area (m)")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--states", o->states, "Key states")
        ->capture_default_str()
        ->check(in_range(1, 100000));
    c->add_option("--duration", o->duration, "Simulated seconds from first to last state")
        ->capture_default_str()
        ->check(positive());
    c->add_option("--max-height", o->max_height, "Initial centre height above radius, at most (m)")
        ->capture_default_str()
        ->check(non_negative());
    c->add_option("--speed", o->speed, "Initial speed per axis, at most (m/s)")
        ->capture_default_str()
        ->check(non_negative());
    c->add_option("--restitution", o->restitution, "Vertical speed kept at a bounce")
        ->capture_default_str()
        ->check(in_range(0.0, 1.0));
    c->callback([o, out] {
      check_extension(*out, ".spheres", "sphere");
      check_output_file(*out, "--output");
      if (o->area < 2 * o->radius)
        throw CLI::ValidationError("--area", "must be at least twice --radius");
      write_and_report("spheres",
                       vislib::with_memory_stage("generating the spheres scene",
                                                 [&] { return vislib::generate_spheres(*o); }),
                       *out, Clock::now());
    });
  }
}

const Registration registration("generate", add_generate);

}  // namespace
}  // namespace pvs_cli
