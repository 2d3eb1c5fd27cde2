// inspect_report.h: the JSON and text output of `pvs inspect` (cmd_inspect.cpp): a whole file's
// summary, one cell's details, and the frames of a cell's visible set against the full scene.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/bake/free_space.h"
#include "vislib/base/vec.h"
#include "vislib/eval/cell_views.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/scene.h"

namespace pvs_cli {

nlohmann::json box_json(const pvs::Box& b);

// The summary of every cell (reads, and so checks, every block) as JSON; and as text.
nlohmann::json summary(pvs::Reader& r);
void print_summary(const std::string& path, const nlohmann::json& j);

// Renders the full scene and the cell's visible set (`ids` of granularity g) from `eye` in the
// views of `views` (default: four horizontal directions at 90 degrees) into `dir`; returns the
// views' metrics and files.
nlohmann::json render_cell(const vislib::Scene& scene, const std::vector<uint32_t>& ids,
                           vislib::Granularity g, vislib::Vec3 eye, const std::string& dir,
                           int width, int height, const vislib::CellViewOptions& views = {});

// A cell's free-space samples (vislib/bake/free_space.h) as JSON: samples, enclosed,
// centre_enclosed and, when there is one, free_point.
nlohmann::json free_space_json(const vislib::CellFreeSpace& f);

// The text output of one cell (the JSON `j` built by the command).
void print_cell(const nlohmann::json& j, const std::vector<uint32_t>& ids, uint32_t cell_count,
                const pvs::FileInfo& info, const pvs::BlockInfo& b, size_t scene_triangles,
                int max_ids);

}  // namespace pvs_cli
