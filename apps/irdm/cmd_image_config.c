/* SPDX-License-Identifier: MIT */
/*
 * irdm image config IMAGE [--board BOARD]: the build configuration
 * (docs/build-config.md) that runs this image on this board and leaves
 * out the rest: the image's representation (modal or FIR), whether it is a
 * floating object, and the board's deformed surface (deform_rate_hz > 0;
 * without --board it is kept).  Written to stdout in the configs/ format,
 * ready for `make CONFIG=FILE`.
 */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "irdm/board.h"
#include "irdm/image.h"
#include "irdm/posix/board_file.h"
#include "irdm/posix/image_map.h"

static void line(const char *feature, bool on)
{
	printf("CONFIG_IRDM_%s=%c\n", feature, on ? 'y' : 'n');
}

int irdm_cmd_image_config(int argc, char **argv)
{
	const char *image = NULL, *board_path = NULL;
	struct irdm_board board;
	struct irdm_image img;
	char err[512];
	bool deform = true;
	int rc;

	for (int i = 0; i < argc; i++) {
		if (!strcmp(argv[i], "--board") && i + 1 < argc)
			board_path = argv[++i];
		else if (argv[i][0] != '-' && !image)
			image = argv[i];
		else {
			fprintf(stderr, "usage: irdm image config IMAGE [--board BOARD]\n");
			return 2;
		}
	}
	if (!image) {
		fprintf(stderr, "usage: irdm image config IMAGE [--board BOARD]\n");
		return 2;
	}
	if (board_path) {
		rc = irdm_board_load(&board, board_path, err, sizeof(err));
		if (rc) {
			irdm_cli_fail("image", rc, err);
			return 1;
		}
		deform = board.deform_rate_hz > 0;
	}
	rc = irdm_image_map(image, 0, &img, err, sizeof(err));
	if (rc) {
		irdm_cli_fail("image", rc, err);
		return 1;
	}
	printf("# for %s%s%s (irdm image config)\n", image, board_path ? " on " : "",
	       board_path ? board_path : "");
	line("MODAL", img.meta->representation == IRDM_REPR_MODAL);
	line("FIR", img.meta->representation == IRDM_REPR_FIR);
	line("FLOATING", img.rigid != NULL);
	line("DEFORM", deform);
	irdm_image_unmap(&img);
	return 0;
}
