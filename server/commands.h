#pragma once
// The `thaw` subcommands; each returns the process exit status.
namespace thaw {
int cmd_run(int argc, char** argv);
int cmd_validate(int argc, char** argv);
int cmd_bench(int argc, char** argv);
int cmd_info(int argc, char** argv);
int cmd_scene_doc(int argc, char** argv);
int cmd_render(int argc, char** argv);
int cmd_serve(int argc, char** argv);
int cmd_ctl(int argc, char** argv);
}  // namespace thaw
