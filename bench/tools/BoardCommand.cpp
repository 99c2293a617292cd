// `avrbench board from-config`: a board file from a firmware's own
// configuration (fwconfig/), written where -o says or to stdout.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "fwconfig/BoardFromConfig.hpp"
#include "fwconfig/ConfigReaders.hpp"
#include "tools/Commands.hpp"

namespace avrbench {

namespace {

struct FromConfigArgs {
    std::vector<std::string> files;
    std::string format, base, out, name;
};

int from_config_command(const FromConfigArgs& args) {
    std::vector<ConfigFile> files;
    for (const auto& path : args.files) files.push_back({path, read_input_file(path, "configuration", 8u << 20)});
    const ConfigFormat format = args.format.empty() ? detect_config_format(files) : config_format_named(args.format);
    const MachineConfig config = read_machine_config(format, files);
    BoardFromConfigOptions options;
    options.inputs = args.files;
    options.base = args.base;
    options.name = args.name.empty() ? std::string(config_format_name(format)) + "-config" : args.name;
    const std::string text = board_from_config(config, options);
    if (args.out.empty() || args.out == "-") {
        std::fwrite(text.data(), 1, text.size(), stdout);
        return kExitOk;
    }
    std::error_code ec;
    for (const auto& in : args.files) {
        if (std::filesystem::equivalent(in, args.out, ec)) throw BadInput("-o " + args.out + ": that is an input file (inputs are never written)");
    }
    std::ofstream out(args.out, std::ios::binary);
    out << text;
    if (!out.flush()) throw BadInput("-o " + args.out + ": cannot write it");
    std::fprintf(stderr, "wrote %s (%s configuration)\n", args.out.c_str(), config_format_name(format));
    return kExitOk;
}

}  // namespace

Command add_board_command(CLI::App& app) {
    auto args = std::make_shared<FromConfigArgs>();
    CLI::App* board = app.add_subcommand("board", "board files: `board from-config` writes one from a firmware's configuration");
    board->require_subcommand(1);
    CLI::App* from = board->add_subcommand(
        "from-config", "a board extending the standard board the configuration names, with its steps/mm, directions, "
                       "enables, endstops, travel and frame (docs/BOARDS.md)");
    from->add_option("files", args->files,
                     "the configuration: Marlin/Prusa/Sprinter Configuration.h [+ _adv.h], Repetier Configuration.h, "
                     "Teacup config.h or printer.*.h + board.*.h, grbl config.h + defaults.h or a $$ dump, Klipper printer.cfg")
        ->required();
    from->add_option("--format", args->format, "marlin, repetier, teacup, grbl, grbl-settings or klipper (default: from the files)");
    from->add_option("--base", args->base, "the board to extend (default: the one the configuration names)");
    from->add_option("--name", args->name, "the new board's name (default FORMAT-config)");
    from->add_option("-o,--out", args->out, "the board file to write (default: stdout)");
    return {from, [args] { return from_config_command(*args); }};
}

}  // namespace avrbench
