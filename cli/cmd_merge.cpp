// pvs merge: join the shard files of a sharded bake (pvs bake --shard i/N) into one PVS file.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/options.h"
#include "pvs_format/pvs_format.h"
#include "vislib/bake/cell_set.h"
#include "vislib/base/file_util.h"

namespace pvs_cli {
namespace {

void add_merge(CLI::App& app) {
  auto shards = std::make_shared<std::vector<std::string>>();
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "merge",
      "Join the shard files of a sharded bake (pvs bake --shard i/N) into one PVS file, "
      "byte-identical to an unsharded bake");
  cmd->add_option("SHARD", *shards, "Shard files, any order")->required();
  cmd->add_option("-o,--output", *out, "Output PVS file")->required();
  cmd->callback([shards, out] {
    check_output_file(*out, "--output");  // before any work
    std::vector<pvs::Reader> readers;
    for (const auto& path : *shards)
      readers.push_back(vislib::reading_pvs(path, [&] { return pvs::Reader::from_file(path); }));
    const std::string bytes =
        vislib::reading_pvs("pvs merge", [&] { return pvs::merge_pvs(readers); });
    vislib::write_file_atomic(*out, bytes);
    if (show_progress())
      std::fprintf(stderr, "pvs merge: %zu shards, %u cells, %zu bytes written to %s\n",
                   readers.size(), readers[0].cell_count(), bytes.size(), out->c_str());
  });
}

Registration merge_registration("merge", add_merge);

}  // namespace
}  // namespace pvs_cli
