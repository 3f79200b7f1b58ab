/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer target: the loader's semantic validation.  Random bytes almost
 * never carry a matching CRC-32C, so fuzz_image_load stops at the
 * checksums.  Here image_load.c is compiled into the target with
 * IRDM_FUZZ_SKIP_CRC, which turns every checksum comparison into "match",
 * and the fuzzer reaches the checks of counts, sizes, offsets and indices.
 *
 * Linking: this file defines every global symbol of image_load.c, so the
 * linker never pulls image_load.o out of libirdmfw.a (archive members are
 * only pulled for undefined symbols); crc32c.o and f16.o come from there.
 * The driver (LLVMFuzzerTestOneInput and the view walk) is the one of
 * fuzz_image_load.c, included below.
 */
#define IRDM_FUZZ_SKIP_CRC 1
#include "../../firmware/image/image_load.c"

#include "fuzz_image_load.c"
