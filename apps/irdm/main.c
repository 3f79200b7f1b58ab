/* SPDX-License-Identifier: MIT */
/* irdm: the offline tool.  Subcommands live in one file each. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "precompute/precompute.h"

static const char usage[] =
	"usage: irdm COMMAND [ARGS]\n"
	"\n"
	"  precompute   make a flash image from a scene (mesh, material, region, representation)\n"
	"  image info   show an image's header, sections, provenance and stability\n"
	"  image verify validate an image the way the firmware does, plus physical checks\n"
	"  image export write R[s] 3x3 blocks of one column as CSV\n"
	"  replay       run the force engine on a prescribed displacement trajectory\n"
	"  render       the deformed surface of a replay or an irdm-fw run: VTK frames, CSV\n"
	"  log export   write an irdm-fw telemetry log as CSV\n"
	"  view         play an irdm-fw run back in the browser (the live view's page)\n"
	"  report       accuracy, tick time and size of representations against the exact model\n"
	"\n"
	"'irdm COMMAND --help' for each.  Version: " IRDM_TOOL_VERSION "\n";

int main(int argc, char **argv)
{
	if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
		fputs(usage, argc < 2 ? stderr : stdout);
		return argc < 2 ? 2 : 0;
	}
	if (!strcmp(argv[1], "--version")) {
		puts(IRDM_TOOL_VERSION);
		return 0;
	}
	if (!strcmp(argv[1], "precompute"))
		return irdm_cmd_precompute(argc - 1, argv + 1);
	if (!strcmp(argv[1], "image"))
		return irdm_cmd_image(argc - 1, argv + 1);
	if (!strcmp(argv[1], "replay"))
		return irdm_cmd_replay(argc - 1, argv + 1);
	if (!strcmp(argv[1], "render"))
		return irdm_cmd_render(argc - 1, argv + 1);
	if (!strcmp(argv[1], "report"))
		return irdm_cmd_report(argc - 1, argv + 1);
	if (!strcmp(argv[1], "view"))
		return irdm_cmd_view(argc - 1, argv + 1);
	if (!strcmp(argv[1], "log"))
		return irdm_cmd_log(argc - 1, argv + 1);
	fprintf(stderr, "irdm: unknown command '%s' (see irdm --help)\n", argv[1]);
	return 2;
}
