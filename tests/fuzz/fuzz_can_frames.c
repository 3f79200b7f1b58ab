// SPDX-License-Identifier: MIT
/*
 * libFuzzer target: every CANopen frame parser (hal/can) on arbitrary
 * frames.  Input: 2 bytes of identifier (11 bits used), 1 of length (any:
 * the parsers must refuse what is not 0..8 and right), 8 of data, then the
 * node the caller expects; repeated.  A parser that accepts must return
 * values the frame holds; nothing may read past the frame.
 */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "irdm/hal/canopen.h"
#include "irdm/hal/cia402.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	for (; size >= 12; data += 12, size -= 12) {
		struct irdm_can_frame f;
		enum irdm_co_nmt_state st;
		struct irdm_co_emcy e;
		uint16_t sw, index = (uint16_t)(data[3] | (data[4] << 8));
		int32_t pos;
		uint32_t v, abort_code;
		unsigned node = data[11], sz = 0;

		f.id = (uint32_t)(data[0] | (data[1] << 8)) & 0x7FF;
		f.dlc = data[2];
		memcpy(f.data, data + 3, 8);
		(void)irdm_co_node_of(&f, IRDM_CO_EMCY);
		(void)irdm_co_tpdo_cst(&f, node, &sw, &pos);
		if (irdm_co_tpdo_cst(&f, node, &sw, &pos) == IRDM_OK)
			(void)irdm_cia402_decode(sw);
		(void)irdm_co_heartbeat(&f, node, &st);
		if (irdm_co_emcy(&f, node, &e) == IRDM_OK)
			(void)irdm_co_emcy_class(e.code);
		if (irdm_co_sdo_answer(&f, node, index, data[5], &v, &sz, &abort_code) == IRDM_EHW)
			(void)irdm_co_abort_name(abort_code);
		if (sz > 4)
			__builtin_trap();
	}
	return 0;
}
