/* SPDX-License-Identifier: MIT */
/*
 * Flash image: CRC-32C, binary16, writer layout and atomicity, loader round
 * trips, and the loader's rejection of every kind of damaged image.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "irdm/image.h"
#include "irdm/posix/image_map.h"
#include "image/elem_store.h"
#include "image/image_writer.h"
#include "support/image_fixture.h"

static char tmpdir[512];
static const char *current_case = ""; /* named when a check fails */

/* ------------------------------------------------------------- helpers */

static void path_in(char *buf, size_t len, const char *name)
{
	snprintf(buf, len, "%s/%s", tmpdir, name);
}

static int rm_tree(const char *path)
{
	struct dirent *de;
	struct stat st;
	char sub[PATH_MAX];
	DIR *d;

	if (lstat(path, &st))
		return -1;
	if (!S_ISDIR(st.st_mode))
		return unlink(path);
	d = opendir(path);
	if (!d)
		return -1;
	while ((de = readdir(d))) {
		if (!strcmp(de->d_name, ".") || !strcmp(de->d_name, ".."))
			continue;
		snprintf(sub, sizeof(sub), "%s/%s", path, de->d_name);
		rm_tree(sub);
	}
	closedir(d);
	return rmdir(path);
}

/* Entries of dir whose name contains ".tmp." (writer leftovers). */
static int count_tmp_files(const char *dir)
{
	struct dirent *de;
	int n = 0;
	DIR *d = opendir(dir);

	assert_non_null(d);
	while ((de = readdir(d)))
		if (strstr(de->d_name, ".tmp."))
			n++;
	closedir(d);
	return n;
}

static void *read_file(const char *path, size_t *len)
{
	FILE *f = fopen(path, "rb");
	void *buf;
	long n;

	assert_non_null(f);
	assert_int_equal(fseek(f, 0, SEEK_END), 0);
	n = ftell(f);
	assert_true(n >= 0);
	rewind(f);
	buf = malloc((size_t)n + 1);
	assert_non_null(buf);
	assert_int_equal(fread(buf, 1, (size_t)n, f), (size_t)n);
	fclose(f);
	*len = (size_t)n;
	return buf;
}

static void write_file(const char *path, const void *buf, size_t len)
{
	FILE *f = fopen(path, "wb");

	assert_non_null(f);
	assert_int_equal(fwrite(buf, 1, len, f), len);
	assert_int_equal(fclose(f), 0);
}

/* Parse a private, exactly sized copy of buf (so ASan sees any overread)
 * and expect code; on failure the message must be set and contain needle,
 * and img must be left zeroed. */
static void expect_parse(const void *buf, size_t size, int code,
			 const char *needle)
{
	struct irdm_image img, zero;
	char err[512];
	void *copy = img_fixture_copy(buf, size);
	int ret;

	assert_non_null(copy);
	memset(&img, 0xa5, sizeof(img));
	memset(&zero, 0, sizeof(zero));
	ret = irdm_image_parse(copy, size, &img, err, sizeof(err));
	if (ret != code || (needle && ret && !strstr(err, needle)))
		print_message("%s: parse got %d \"%s\", expected %d with \"%s\"\n",
			      current_case, ret, err, code, needle ? needle : "");
	assert_int_equal(ret, code);
	if (code) {
		assert_true(strlen(err) > 10);
		assert_null(strchr(err, '\n'));
		if (needle)
			assert_non_null(strstr(err, needle));
		assert_memory_equal(&img, &zero, sizeof(img));
	}
	free(copy);
}

static void fixture_buffer(const struct img_fixture *fx, void **buf,
			   size_t *size)
{
	assert_int_equal(img_fixture_buffer(fx, buf, size), 0);
}

/* The fixture's image in a new buffer (the caller frees it), parsed into
 * img, which must succeed. */
static void *parse_fixture(const struct img_fixture *fx, struct irdm_image *img)
{
	char err[256];
	size_t size;
	void *buf;

	fixture_buffer(fx, &buf, &size);
	if (irdm_image_parse(buf, size, img, err, sizeof(err)))
		fail_msg("fixture image refused: %s", err);
	return buf;
}

static void small_fir(struct img_fixture *fx)
{
	assert_int_equal(img_fixture_fir(fx, IRDM_ELEM_F32, 6, 2, 4), 0);
}

static void small_modal(struct img_fixture *fx)
{
	assert_int_equal(img_fixture_modal(fx, IRDM_ELEM_F64, 5, 2, 3,
					   IRDM_META_FLOATING |
						   IRDM_META_STATIC_CORR),
			 0);
}

static struct irdm_image_section get_entry(const void *buf, unsigned i)
{
	struct irdm_image_header h;
	struct irdm_image_section s;

	memcpy(&h, buf, sizeof(h));
	memcpy(&s, (const uint8_t *)buf + h.section_table_offset + i * sizeof(s),
	       sizeof(s));
	return s;
}

static void put_entry(void *buf, unsigned i, const struct irdm_image_section *s)
{
	struct irdm_image_header h;

	memcpy(&h, buf, sizeof(h));
	memcpy((uint8_t *)buf + h.section_table_offset + i * sizeof(*s), s,
	       sizeof(*s));
}

static unsigned entry_of(const void *buf, uint32_t kind)
{
	struct irdm_image_header h;

	memcpy(&h, buf, sizeof(h));
	for (unsigned i = 0; i < h.section_count; i++)
		if (get_entry(buf, i).kind == kind)
			return i;
	fail_msg("kind %u not in image", kind);
	return 0;
}

static struct irdm_image_header get_header(const void *buf)
{
	struct irdm_image_header h;

	memcpy(&h, buf, sizeof(h));
	return h;
}

static void put_header(void *buf, const struct irdm_image_header *h)
{
	memcpy(buf, h, sizeof(*h));
}

/* ---------------------------------------------------------------- CRC */

/* Bit-at-a-time reference, independent of the table code. */
static uint32_t crc32c_bitwise(const uint8_t *p, size_t n)
{
	uint32_t c = 0xffffffffu;

	while (n--) {
		c ^= *p++;
		for (int k = 0; k < 8; k++)
			c = (c >> 1) ^ (0x82f63b78u & (0u - (c & 1)));
	}
	return ~c;
}

static void test_crc32c_check_value(void **state)
{
	(void)state;
	assert_int_equal(irdm_crc32c("123456789", 9), 0xE3069283u);
	assert_int_equal(irdm_crc32c("", 0), 0);
	/* RFC 3720 B.4: 32 bytes of zeros, of 0xff. */
	uint8_t z[32] = { 0 }, f[32];

	memset(f, 0xff, sizeof(f));
	assert_int_equal(irdm_crc32c(z, 32), 0x8A9136AAu);
	assert_int_equal(irdm_crc32c(f, 32), 0x62A8AB43u);
}

static void test_crc32c_all_lengths_and_alignments(void **state)
{
	uint8_t buf[300];

	(void)state;
	for (size_t i = 0; i < sizeof(buf); i++)
		buf[i] = (uint8_t)(i * 167 + 13);
	for (size_t off = 0; off < 8; off++)
		for (size_t n = 0; n + off <= sizeof(buf); n++)
			assert_int_equal(irdm_crc32c(buf + off, n),
					 crc32c_bitwise(buf + off, n));
}

/* --------------------------------------------------------------- binary16 */

static uint32_t f32bits(float f)
{
	uint32_t x;

	memcpy(&x, &f, sizeof(x));
	return x;
}

static void test_f16_known_patterns(void **state)
{
	static const struct {
		float f;
		uint16_t h;
	} t[] = {
		{ 1.0f, 0x3c00 }, { -2.0f, 0xc000 }, { 65504.0f, 0x7bff }, { 0x1p-24f, 0x0001 }, { 0x1p-14f, 0x0400 }, { 0.1f, 0x2e66 }, { 0.0f, 0x0000 }, { -0.0f, 0x8000 }, { 0.5f, 0x3800 }, { 65520.0f, 0x7c00 }, { 1e6f, 0x7c00 }, { -1e6f, 0xfc00 }, { INFINITY, 0x7c00 }, { -INFINITY, 0xfc00 }, { 0x1p-25f, 0x0000 }, /* tie: to even (0) */
		{ 0x1.8p-24f, 0x0002 },                                                                                                                                                                                                                                                                                       /* tie 1.5 units: to even (2) */
		{ 0x1.0p-26f, 0x0000 },
		{ 0x1.000002p-25f, 0x0001 },
		{ 65519.0f, 0x7bff },
		{ 0x1.ff8p-15f, 0x03ff },
		{ 0x1.ffcp-15f, 0x0400 },      /* tie: to even (normal) */
		{ 1.0f + 0x1p-11f, 0x3c00 },   /* tie: to even */
		{ 1.0f + 0x1.8p-10f, 0x3c02 }, /* tie: to even (up) */
	};

	(void)state;
	for (size_t i = 0; i < sizeof(t) / sizeof(t[0]); i++) {
		uint16_t h = irdm_f32_to_f16(t[i].f);

		if (h != t[i].h)
			print_message("%a -> 0x%04x, expected 0x%04x\n",
				      (double)t[i].f, h, t[i].h);
		assert_int_equal(h, t[i].h);
	}
	assert_true(irdm_f16_to_f32(0x3c00) == 1.0f);
	assert_true(irdm_f16_to_f32(0xc000) == -2.0f);
	assert_true(irdm_f16_to_f32(0x7bff) == 65504.0f);
	assert_true(irdm_f16_to_f32(0x0001) == 0x1p-24f);
	assert_true(irdm_f16_to_f32(0x03ff) == 0x1.ff8p-15f);
	assert_true(irdm_f16_to_f32(0x7c00) == INFINITY);
	assert_true(irdm_f16_to_f32(0xfc00) == -INFINITY);
	assert_int_equal(f32bits(irdm_f16_to_f32(0x8000)), 0x80000000u);
	assert_true(isnan(irdm_f16_to_f32(0x7e00)));
	assert_true(isnan(irdm_f16_to_f32(0x7c01)));
	assert_true((irdm_f32_to_f16(NAN) & 0x7fff) > 0x7c00);
}

static void test_f16_roundtrip_all(void **state)
{
	(void)state;
	for (uint32_t i = 0; i < 65536; i++) {
		uint16_t h = (uint16_t)i;
		float f = irdm_f16_to_f32(h);
		bool nan = (h & 0x7c00) == 0x7c00 && (h & 0x3ff);

		assert_int_equal(isnan(f) != 0, nan);
		if (nan) {
			uint16_t back = irdm_f32_to_f16(f);

			assert_true((back & 0x7c00) == 0x7c00 && (back & 0x3ff));
			assert_int_equal(back & 0x8000, h & 0x8000);
			continue;
		}
		assert_int_equal(irdm_f32_to_f16(f), h);
	}
}

/* Every rounding boundary: just below, at and above the midpoint between
 * each pair of neighbouring halves (both signs). */
static void test_f16_rounding_all_midpoints(void **state)
{
	(void)state;
	for (uint16_t h = 0; h < 0x7c00; h++) {
		float lo = irdm_f16_to_f32(h);
		float hi = irdm_f16_to_f32((uint16_t)(h + 1));
		float mid = lo + (hi - lo) / 2; /* exact in binary32 */
		uint16_t even = (h & 1) ? (uint16_t)(h + 1) : h;

		if (h == 0x7bff)
			hi = 65536.0f, mid = 65520.0f;
		assert_int_equal(irdm_f32_to_f16(nextafterf(mid, 0)), h);
		assert_int_equal(irdm_f32_to_f16(mid), even);
		assert_int_equal(irdm_f32_to_f16(nextafterf(mid, hi)), h + 1);
		assert_int_equal(irdm_f32_to_f16(-nextafterf(mid, 0)), h | 0x8000);
		assert_int_equal(irdm_f32_to_f16(-mid), even | 0x8000);
	}
}

static void test_elem_size_and_get(void **state)
{
	const uint16_t h[2] = { 0x3c00, 0xc000 };
	const float f[2] = { 1.5f, -3.25f };
	const double d[2] = { 1e300, -2.5 };
	const uint32_t u[2] = { 7, 4000000000u };
	const uint8_t b[2] = { 9, 250 };

	(void)state;
	assert_int_equal(irdm_elem_size(IRDM_ELEM_BYTES), 1);
	assert_int_equal(irdm_elem_size(IRDM_ELEM_F16), 2);
	assert_int_equal(irdm_elem_size(IRDM_ELEM_F32), 4);
	assert_int_equal(irdm_elem_size(IRDM_ELEM_F64), 8);
	assert_int_equal(irdm_elem_size(IRDM_ELEM_U32), 4);
	assert_int_equal(irdm_elem_size(5), 0);
	assert_true(irdm_elem_get(h, IRDM_ELEM_F16, 1) == -2.0);
	assert_true(irdm_elem_get(f, IRDM_ELEM_F32, 1) == -3.25);
	assert_true(irdm_elem_get(d, IRDM_ELEM_F64, 0) == 1e300);
	assert_true(irdm_elem_get(u, IRDM_ELEM_U32, 1) == 4000000000.0);
	assert_true(irdm_elem_get(b, IRDM_ELEM_BYTES, 1) == 250.0);
	assert_true(isnan(irdm_elem_get(b, 77, 0)));
}

/* ---------------------------------------------------------- writer layout */

static void test_writer_layout(void **state)
{
	struct img_fixture fx;
	struct irdm_image_header h;
	uint64_t end = 0;
	size_t size;
	void *buf;

	(void)state;
	small_modal(&fx);
	fixture_buffer(&fx, &buf, &size);
	h = get_header(buf);
	assert_memory_equal(h.magic, "IRDMIMG", 8);
	assert_int_equal(h.version_major, IRDM_IMAGE_VERSION_MAJOR);
	assert_int_equal(h.version_minor, IRDM_IMAGE_VERSION_MINOR);
	assert_int_equal(h.header_size, 64);
	assert_int_equal(h.file_size, size);
	assert_int_equal(h.section_count, 11);
	assert_int_equal(h.section_table_offset, 64);
	assert_int_equal(h.header_crc32c, irdm_crc32c(buf, 60));
	assert_int_equal(h.table_crc32c,
			 irdm_crc32c((uint8_t *)buf + 64, 11 * 32));
	end = 64 + 11 * 32;
	for (unsigned i = 0; i < h.section_count; i++) {
		struct irdm_image_section s = get_entry(buf, i);

		assert_int_equal(s.offset % 64, 0);
		assert_true(s.offset >= end && s.offset - end < 64);
		for (uint64_t o = end; o < s.offset; o++)
			assert_int_equal(((uint8_t *)buf)[o], 0);
		assert_int_equal(s.crc32c,
				 irdm_crc32c((uint8_t *)buf + s.offset, s.size));
		assert_int_equal(s.reserved, 0);
		end = s.offset + s.size;
	}
	assert_int_equal(end, size); /* no trailing bytes */
	free(buf);
	img_fixture_free(&fx);
}

static void test_writer_add_rejects(void **state)
{
	struct irdm_image_writer w;
	uint8_t x[4] = { 0 };
	char err[256] = "";
	char path[PATH_MAX];
	void *buf;
	size_t size;

	(void)state;
	irdm_iw_init(&w);
	assert_int_equal(irdm_iw_add(&w, 1, IRDM_ELEM_BYTES, x, 4), 0);
	assert_int_equal(irdm_iw_add(&w, 1, IRDM_ELEM_BYTES, x, 4), IRDM_EINVAL);
	assert_int_equal(irdm_iw_add(&w, 2, IRDM_ELEM_BYTES, NULL, 4), IRDM_EINVAL);
	assert_int_equal(irdm_iw_add(&w, 2, 9, x, 4), IRDM_EINVAL);
	for (uint32_t k = 2; k <= IRDM_IMAGE_MAX_SECTIONS; k++)
		assert_int_equal(irdm_iw_add(&w, k, IRDM_ELEM_BYTES, x, 4), 0);
	assert_int_equal(irdm_iw_add(&w, 99, IRDM_ELEM_BYTES, x, 4), IRDM_EINVAL);
	assert_int_equal(w.n, IRDM_IMAGE_MAX_SECTIONS);

	irdm_iw_init(&w);
	assert_int_equal(irdm_iw_to_buffer(&w, &buf, &size), IRDM_EINVAL);
	assert_null(buf);
	path_in(path, sizeof(path), "empty.img");
	assert_int_equal(irdm_iw_write(&w, path, err, sizeof(err)), IRDM_EINVAL);
	assert_non_null(strstr(err, path));
	assert_int_equal(access(path, F_OK), -1);
	assert_int_equal(count_tmp_files(tmpdir), 0);
}

/* ------------------------------------------------------------ round trips */

static void check_common_views(const struct irdm_image *img,
			       const struct img_fixture *fx)
{
	const struct irdm_meta *m = &fx->meta;

	assert_non_null(img->meta);
	assert_memory_equal(img->meta, m, sizeof(*m));
	assert_int_equal(img->provenance_len, fx->provenance_len);
	assert_memory_equal(img->provenance, fx->provenance, fx->provenance_len);
	assert_memory_equal(img->nodes, fx->nodes, m->n_nodes * sizeof(*fx->nodes));
	assert_memory_equal(img->columns, fx->columns, m->n_cols * 4);
	assert_memory_equal(img->tris, fx->tris, m->n_tris * 12);
	assert_memory_equal(img->stability, fx->stability,
			    m->n_cols * sizeof(*fx->stability));
	for (uint32_t k = 1; k <= IRDM_SEC_STABILITY; k++) {
		const struct irdm_image_section *s = irdm_image_find(img, k);

		if (!s)
			continue;
		assert_int_equal(s->kind, k);
		assert_int_equal(s->offset % 64, 0);
		assert_true(s->offset + s->size <= img->size);
	}
	assert_null(irdm_image_find(img, IRDM_SEC_CONTACT_BVH));
	assert_null(irdm_image_find(img, 1000));
	assert_ptr_equal(irdm_image_find(img, IRDM_SEC_META)->offset +
				 img->base,
			 (const uint8_t *)img->meta);
}

static void check_fir_values(const struct irdm_image *img, uint32_t prec)
{
	const struct irdm_meta *m = img->meta;
	uint64_t T = m->fir_length;

	/* Block (col c, row r, sample s) element (i, j). */
	for (uint64_t c = 0; c < m->n_cols; c++)
		for (uint64_t r = 0; r < m->n_nodes; r++)
			for (uint64_t s = 0; s < T; s++)
				for (uint64_t i = 0; i < 3; i++)
					for (uint64_t j = 0; j < 3; j++) {
						uint64_t k = ((((c * m->n_nodes + r) * T + s) * 3 + i) * 3 + j);

						assert_true(irdm_elem_get(img->fir, prec, k) ==
							    img_fixture_value(IRDM_SEC_FIR, k));
					}
}

static void test_fir_roundtrip(void **state)
{
	static const uint32_t precs[] = { IRDM_ELEM_F16, IRDM_ELEM_F32,
					  IRDM_ELEM_F64 };
	struct img_fixture fx;
	struct irdm_image img;
	char path[PATH_MAX], err[512];
	struct stat st;

	(void)state;
	path_in(path, sizeof(path), "fir.img");
	for (size_t p = 0; p < 3; p++) {
		assert_int_equal(img_fixture_fir(&fx, precs[p], 7, 3, 5), 0);
		assert_int_equal(img_fixture_write(&fx, path, err, sizeof(err)), 0);
		assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)),
				 IRDM_OK);
		assert_int_equal(stat(path, &st), 0);
		assert_int_equal(img.size, (size_t)st.st_size);
		assert_true(img.mapped);
		assert_false(img.locked);
		assert_int_equal((uintptr_t)img.base % 4096, 0);
		check_common_views(&img, &fx);
		check_fir_values(&img, precs[p]);
		assert_memory_equal(img.fir, fx.fir, fx.fir_bytes);
		assert_null(img.modes);
		assert_null(img.mode_shapes);
		assert_null(img.corr_blocks);
		assert_null(img.corr_start);
		assert_null(img.rigid);
		irdm_image_unmap(&img);
		assert_null(img.base);
		assert_false(img.mapped);
		img_fixture_free(&fx);
	}
	assert_int_equal(count_tmp_files(tmpdir), 0);
}

static void test_modal_floating_roundtrip(void **state)
{
	struct img_fixture fx;
	struct irdm_image img;
	char path[PATH_MAX], err[512];
	uint64_t n;

	(void)state;
	small_modal(&fx);
	path_in(path, sizeof(path), "modal.img");
	assert_int_equal(img_fixture_write(&fx, path, err, sizeof(err)), 0);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)),
			 IRDM_OK);
	check_common_views(&img, &fx);
	assert_null(img.fir);
	assert_memory_equal(img.modes, fx.modes, 3 * sizeof(*fx.modes));
	assert_memory_equal(img.rigid, &fx.rigid, sizeof(fx.rigid));
	n = (uint64_t)5 * 3 * 3; /* [row][3][mode] */
	for (uint64_t k = 0; k < n; k++)
		assert_true(irdm_elem_get(img.mode_shapes, IRDM_ELEM_F64, k) ==
			    img_fixture_value(IRDM_SEC_MODE_SHAPES, k));
	n = (uint64_t)2 * 2 * 9; /* every block kept: [col][col][3][3] */
	for (uint64_t k = 0; k < n; k++)
		assert_true(irdm_elem_get(img.corr_blocks, IRDM_ELEM_F64, k) ==
			    img_fixture_value(IRDM_SEC_STATIC_CORR, k));
	for (uint32_t c = 0; c < 2; c++)
		for (uint32_t r = 0; r < 2; r++)
			assert_int_equal(irdm_image_corr_block(&img, c, r), 2 * c + r);
	/* The fixture's modes are exact ZOH discretisations: |eig(A)| < 1. */
	assert_true(img.modes[0].a[0] * img.modes[0].a[3] -
			    img.modes[0].a[1] * img.modes[0].a[2] <
		    1);
	irdm_image_unmap(&img);
	img_fixture_free(&fx);
}

/* The far field: views, and every block irdm_image_corr_value() returns
 * is the kept block + sum_k lambda_k U[r][i][k] U[c][j][k] of the fixture's
 * values (every precision: the values are exact in each). */
static void test_modal_lowrank_roundtrip(void **state)
{
	static const uint32_t precs[] = { IRDM_ELEM_F16, IRDM_ELEM_F32, IRDM_ELEM_F64 };
	const uint32_t K = IRDM_SEC_STATIC_CORR_LOWRANK, R = 3;
	struct img_fixture fx;
	struct irdm_image img;
	void *buf;

	(void)state;
	for (size_t p = 0; p < 3; p++) {
		assert_int_equal(img_fixture_modal(&fx, precs[p], 5, 2, 3, IRDM_META_STATIC_CORR), 0);
		assert_int_equal(img_fixture_lowrank(&fx, R), 0);
		buf = parse_fixture(&fx, &img);
		assert_int_equal(img.corr_rank, R);
		for (uint32_t c = 0; c < 2; c++)
			for (uint32_t r = 0; r < 2; r++) {
				double blk[9];
				irdm_image_corr_value(&img, c, r, blk);
				for (uint32_t i = 0; i < 3; i++)
					for (uint32_t j = 0; j < 3; j++) {
						double want = img_fixture_value(IRDM_SEC_STATIC_CORR,
										(2 * c + r) * 9 + 3 * i + j);
						for (uint32_t k = 0; k < R; k++)
							want += img_fixture_value(K, k) *
								img_fixture_value(K, R + (3 * r + i) * R + k) *
								img_fixture_value(K, R + (3 * c + j) * R + k);
						assert_true(fabs(blk[3 * i + j] - want) <= 1e-15);
					}
			}
		free(buf);
		img_fixture_free(&fx);
	}
	/* without the section: no far field, the kept block alone */
	small_modal(&fx);
	buf = parse_fixture(&fx, &img);
	assert_int_equal(img.corr_rank, 0);
	assert_null(img.corr_u);
	free(buf);
	img_fixture_free(&fx);
}

/* Every kept block made the transpose of its mirror, block (r, c) =
 * block (c, r)^T, as a real static correction is: then every value
 * irdm_image_corr_value() returns can transpose to the bit. */
static void symmetric_kept(struct img_fixture *fx)
{
	uint32_t nc = fx->meta.n_cols, prec = fx->meta.precision;

	for (uint32_t c = 0; c < nc; c++)
		for (uint32_t r = c; r < nc; r++)
			for (uint32_t i = 0; i < 3; i++)
				for (uint32_t j = 0; j < 3; j++)
					if (c != r || j > i)
						irdm_elem_put(fx->static_corr, prec,
							      ((size_t)r * nc + c) * 9 + 3 * j + i,
							      irdm_elem_get(fx->static_corr, prec,
									    ((size_t)c * nc + r) * 9 + 3 * i + j));
}

/* Entry [i][j] of the brute-force block (force at f, displacement of d):
 * the kept block, the far field sum_k lambda_k U[d][i][k] U[f][j][k]
 * (rank far, the fixture's values) and S's entry. */
static double clusters_want(const struct img_fixture *fx, const double *S, uint32_t far,
			    uint32_t f, uint32_t d, uint32_t i, uint32_t j)
{
	const uint32_t K = IRDM_SEC_STATIC_CORR_LOWRANK, nc = fx->meta.n_cols;
	double want = irdm_elem_get(fx->static_corr, fx->meta.precision,
				    ((size_t)f * nc + d) * 9 + 3 * i + j);

	for (uint32_t k = 0; k < far; k++)
		want += img_fixture_value(K, k) * img_fixture_value(K, far + (3 * d + i) * far + k) *
			img_fixture_value(K, far + (3 * f + j) * far + k);
	return want + S[(3 * (size_t)d + i) * 3 * nc + 3 * f + j];
}

/* The pair table and the cluster lookup against the fixture's layout:
 * members in reverse column order, cluster a from member a nc / n on. */
static void check_cluster_tables(const struct irdm_image *img, uint32_t nc, uint32_t n,
				 uint32_t rank)
{
	for (uint32_t col = 0; col < nc; col++) {
		uint32_t pos = nc - 1 - col, a = 0, local;
		while ((uint64_t)(a + 1) * nc / n <= pos)
			a++;
		assert_int_equal(irdm_image_corr_cluster(img, col, &local), a);
		assert_int_equal(local, pos - (uint32_t)((uint64_t)a * nc / n));
	}
	for (uint32_t a = 0; a < n; a++)
		for (uint32_t b = 0; b < n; b++) {
			const struct irdm_corr_pair *q = irdm_image_corr_pair(img, a, b);
			assert_ptr_equal(q, irdm_image_corr_pair(img, b, a));
			assert_int_equal(q->rank, a == b ? IRDM_CORR_PAIR_DENSE : rank);
		}
}

/* STATIC_CORR_CLUSTERS: every block irdm_image_corr_value() returns, for
 * every ordered pair of 7 columns, is the kept block + the far field + the
 * block of S, the fixture's dense symmetric matrix whose cross-cluster
 * blocks are exact products G H^T; and block (f, d) is block (d, f)
 * transposed to the bit.  The fixture's values are k/1024 with |k| <= 500,
 * so every product and sum here is exact: the comparisons are ==. */
static void test_modal_clusters_roundtrip(void **state)
{
	static const struct {
		uint32_t prec, n_clusters, rank, far;
	} runs[] = {
		{ IRDM_ELEM_F16, 3, 2, 0 }, /* clusters of 2, 2, 3 columns */
		{ IRDM_ELEM_F32, 3, 6, 2 }, /* full rank of the smaller cluster */
		{ IRDM_ELEM_F64, 2, IRDM_CORR_PAIR_DENSE, 3 },
		{ IRDM_ELEM_F64, 7, 0, 0 }, /* one column each, cross pairs zero */
		{ IRDM_ELEM_F64, 1, 0, 2 }, /* one dense self pair */
		{ IRDM_ELEM_F64, 4, 3, 1 },
	};
	const uint32_t NC = 7;
	double S[21 * 21];
	struct img_fixture fx;
	struct irdm_image img;
	void *buf;

	(void)state;
	for (size_t n = 0; n < sizeof(runs) / sizeof(runs[0]); n++) {
		assert_int_equal(img_fixture_modal(&fx, runs[n].prec, 8, NC, 3,
						   IRDM_META_STATIC_CORR),
				 0);
		symmetric_kept(&fx);
		if (runs[n].far)
			assert_int_equal(img_fixture_lowrank(&fx, runs[n].far), 0);
		assert_int_equal(img_fixture_clusters(&fx, runs[n].n_clusters, runs[n].rank, S), 0);
		for (uint32_t r = 0; r < 3 * NC; r++)
			for (uint32_t c = 0; c < r; c++)
				assert_true(S[r * 3 * NC + c] == S[c * 3 * NC + r]);
		buf = parse_fixture(&fx, &img);
		assert_non_null(img.corr_clusters);
		assert_int_equal(img.corr_clusters->n_clusters, runs[n].n_clusters);
		check_cluster_tables(&img, NC, runs[n].n_clusters, runs[n].rank);
		for (uint32_t f = 0; f < NC; f++)
			for (uint32_t d = 0; d < NC; d++) {
				double blk[9], mirror[9];
				irdm_image_corr_value(&img, f, d, blk);
				irdm_image_corr_value(&img, d, f, mirror);
				for (uint32_t i = 0; i < 3; i++)
					for (uint32_t j = 0; j < 3; j++) {
						assert_true(blk[3 * i + j] ==
							    clusters_want(&fx, S, runs[n].far, f, d, i, j));
						assert_true(blk[3 * i + j] == mirror[3 * j + i]);
					}
			}
		free(buf);
		img_fixture_free(&fx);
	}
	/* without the section: no views */
	small_modal(&fx);
	buf = parse_fixture(&fx, &img);
	assert_null(img.corr_clusters);
	assert_null(img.corr_cl_values);
	free(buf);
	img_fixture_free(&fx);
}

/* Exact transposition must not lean on exact arithmetic: with every value
 * of the clusters made inexact (x -> x (1 + sqrt(2) 1e-3) + 1/3, which
 * keeps the self pairs symmetric), block (f, d) is still block (d, f)
 * transposed to the bit, rank 6 cross pairs rounding at every term. */
static void test_clusters_transpose_inexact(void **state)
{
	const uint32_t NC = 7;
	struct img_fixture fx;
	struct irdm_image img;
	double *v;
	void *buf;

	(void)state;
	assert_int_equal(img_fixture_modal(&fx, IRDM_ELEM_F64, 8, NC, 3, IRDM_META_STATIC_CORR), 0);
	symmetric_kept(&fx);
	assert_int_equal(img_fixture_lowrank(&fx, 2), 0);
	assert_int_equal(img_fixture_clusters(&fx, 3, 6, NULL), 0);
	v = (double *)((uint8_t *)fx.corr_clusters + img_fixture_clusters_tables(3, NC) +
		       6 * sizeof(struct irdm_corr_pair));
	for (uint64_t i = 0; i < ((struct irdm_corr_clusters_header *)fx.corr_clusters)->n_values; i++)
		v[i] = v[i] * (1 + sqrt(2) * 1e-3) + 1.0 / 3;
	buf = parse_fixture(&fx, &img);
	for (uint32_t f = 0; f < NC; f++)
		for (uint32_t d = 0; d < NC; d++) {
			double blk[9], mirror[9];
			irdm_image_corr_value(&img, f, d, blk);
			irdm_image_corr_value(&img, d, f, mirror);
			for (uint32_t i = 0; i < 3; i++)
				for (uint32_t j = 0; j < 3; j++)
					assert_true(blk[3 * i + j] == mirror[3 * j + i]);
		}
	free(buf);
	img_fixture_free(&fx);
}

/* Grounded modal image without static correction, f16. */
static void test_modal_grounded_f16_roundtrip(void **state)
{
	struct img_fixture fx;
	size_t size;
	void *buf;

	(void)state;
	assert_int_equal(img_fixture_modal(&fx, IRDM_ELEM_F16, 4, 4, 2, 0), 0);
	fixture_buffer(&fx, &buf, &size);
	expect_parse(buf, size, IRDM_OK, NULL);
	free(buf);
	img_fixture_free(&fx);
}

static void test_map_lock(void **state)
{
	struct img_fixture fx;
	struct irdm_image img;
	char path[PATH_MAX], err[512] = "";
	int ret;

	(void)state;
	small_fir(&fx);
	path_in(path, sizeof(path), "lock.img");
	assert_int_equal(img_fixture_write(&fx, path, err, sizeof(err)), 0);
	ret = irdm_image_map(path, IRDM_IMAGE_MAP_LOCK, &img, err, sizeof(err));
	if (ret == IRDM_OK) {
		assert_true(img.locked);
		irdm_image_unmap(&img);
	} else {
		/* Not allowed to lock here: the reason must say how to fix it. */
		assert_int_equal(ret, IRDM_EIO);
		assert_non_null(strstr(err, "cannot lock"));
		assert_non_null(strstr(err, "RLIMIT_MEMLOCK"));
		assert_null(img.base);
	}
	assert_int_equal(irdm_image_map(path, 0x80, &img, err, sizeof(err)),
			 IRDM_EINVAL);
	img_fixture_free(&fx);
}

static void test_map_errors(void **state)
{
	struct irdm_image img;
	char path[PATH_MAX], err[512];
	struct img_fixture fx;
	uint8_t *buf;
	size_t size;

	(void)state;
	path_in(path, sizeof(path), "does-not-exist.img");
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)),
			 IRDM_EIO);
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, strerror(ENOENT)));
	assert_null(img.base);

	assert_int_equal(irdm_image_map(tmpdir, 0, &img, err, sizeof(err)),
			 IRDM_EIO);
	assert_non_null(strstr(err, "regular file"));

	path_in(path, sizeof(path), "tiny.img");
	write_file(path, "IRDMIMG", 8);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)),
			 IRDM_ETRUNC);
	assert_non_null(strstr(err, "truncated"));
	write_file(path, "", 0);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)),
			 IRDM_ETRUNC);

	/* A parse error through map names the path and the problem, and the
	 * file is unmapped again. */
	small_fir(&fx);
	assert_int_equal(img_fixture_buffer(&fx, (void **)&buf, &size), 0);
	buf[size - 1] ^= 1;
	path_in(path, sizeof(path), "bad.img");
	write_file(path, buf, size);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)),
			 IRDM_ECRC);
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, "STABILITY"));
	assert_null(img.base);
	free(buf);
	img_fixture_free(&fx);
}

/* ------------------------------------------------------------- corruption */

static void test_truncated_every_length(void **state)
{
	struct img_fixture fx;
	size_t size;
	void *buf;

	(void)state;
	small_modal(&fx);
	fixture_buffer(&fx, &buf, &size);
	/* Every length: covers 0 .. header + table and everything beyond. */
	for (size_t len = 0; len < size; len++)
		expect_parse(buf, len, IRDM_ETRUNC, "truncated");
	expect_parse(buf, size, IRDM_OK, NULL);
	free(buf);
	img_fixture_free(&fx);
}

static void test_every_byte_flip_detected(void **state)
{
	static const uint8_t masks[] = { 0x01, 0x80, 0xff };
	struct img_fixture fx;
	int hist[1 - IRDM_ERR_MIN] = { 0 };
	size_t size;
	uint8_t *buf;

	(void)state;
	small_modal(&fx);
	fixture_buffer(&fx, (void **)&buf, &size);
	for (size_t pos = 0; pos < size; pos++) {
		for (size_t m = 0; m < sizeof(masks); m++) {
			struct irdm_image img;
			char err[512] = "";
			uint8_t *copy = img_fixture_copy(buf, size);
			int ret;

			copy[pos] ^= masks[m];
			ret = irdm_image_parse(copy, size, &img, err, sizeof(err));
			if (ret == IRDM_OK)
				print_message("flip 0x%02x at %zu accepted\n",
					      masks[m], pos);
			assert_true(ret < 0 && ret >= IRDM_EFORMAT);
			assert_true(err[0] != '\0');
			assert_null(img.base);
			hist[-ret]++;
			free(copy);
		}
	}
	print_message("%zu bytes x 3 flips: trunc %d magic %d version %d crc %d "
		      "range %d missing %d format %d\n",
		      size, hist[-IRDM_ETRUNC],
		      hist[-IRDM_EMAGIC], hist[-IRDM_EVERSION], hist[-IRDM_ECRC],
		      hist[-IRDM_ERANGE], hist[-IRDM_EMISSING], hist[-IRDM_EFORMAT]);
	free(buf);
	img_fixture_free(&fx);
}

static void test_bad_magic_and_version(void **state)
{
	struct img_fixture fx;
	struct irdm_image_header h;
	size_t size;
	uint8_t *buf;

	(void)state;
	small_fir(&fx);
	fixture_buffer(&fx, (void **)&buf, &size);

	buf[0] = 'X';
	expect_parse(buf, size, IRDM_EMAGIC, "not an IRDM image");
	buf[0] = 'I';
	buf[7] = ' '; /* the NUL is part of the magic */
	expect_parse(buf, size, IRDM_EMAGIC, "magic");
	buf[7] = 0;

	h = get_header(buf);
	h.version_major = 3;
	h.version_minor = 0;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_EVERSION, "version 3.0");
	h.version_major = 1; /* the dense STATIC_CORR of before */
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_EVERSION, "1.x kept the static correction dense; re-run irdm precompute");
	h.version_major = 0;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_EVERSION, "not supported");

	/* A newer minor is compatible, and may use reserved header fields. */
	h.version_major = IRDM_IMAGE_VERSION_MAJOR;
	h.version_minor = IRDM_IMAGE_VERSION_MINOR + 1;
	h.flags = 0x10;
	h.reserved[5] = 7;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_OK, NULL);
	/* ... but version 1.0 may not. */
	h.version_minor = 0;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_EFORMAT, "reserved");

	h.flags = 0;
	h.reserved[5] = 0;
	h.header_size = 72;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_ERANGE, "header_size is 72");
	free(buf);
	img_fixture_free(&fx);
}

static void test_bad_checksums(void **state)
{
	struct img_fixture fx;
	struct irdm_image_section s;
	size_t size;
	uint8_t *buf;
	unsigned i;

	(void)state;
	small_fir(&fx);
	fixture_buffer(&fx, (void **)&buf, &size);

	buf[20] ^= 0x40; /* file_size, covered by header crc */
	expect_parse(buf, size, IRDM_ECRC, "header checksum mismatch");
	buf[20] ^= 0x40;

	buf[64 + 3 * 32 + 8] ^= 0x40; /* an offset in the table */
	expect_parse(buf, size, IRDM_ECRC, "section table checksum mismatch");
	buf[64 + 3 * 32 + 8] ^= 0x40;

	i = entry_of(buf, IRDM_SEC_NODES);
	s = get_entry(buf, i);
	buf[s.offset + 5] ^= 1;
	expect_parse(buf, size, IRDM_ECRC, "(NODES) checksum mismatch");
	buf[s.offset + 5] ^= 1;

	s.crc32c ^= 1; /* the stored crc is in the table */
	put_entry(buf, i, &s);
	expect_parse(buf, size, IRDM_ECRC, "section table checksum");
	free(buf);
	img_fixture_free(&fx);
}

static void test_file_size_mismatch(void **state)
{
	struct img_fixture fx;
	struct irdm_image_header h;
	size_t size;
	uint8_t *buf, *big;

	(void)state;
	small_fir(&fx);
	fixture_buffer(&fx, (void **)&buf, &size);
	h = get_header(buf);

	h.file_size = size + 64;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_ETRUNC, "header says");

	h.file_size = size;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	big = calloc(size + 64, 1);
	assert_non_null(big);
	memcpy(big, buf, size);
	expect_parse(big, size + 64, IRDM_ERANGE, "trailing");
	expect_parse(big, size + 1, IRDM_ERANGE, "trailing");
	free(big);
	free(buf);
	img_fixture_free(&fx);
}

static void test_table_out_of_range(void **state)
{
	struct img_fixture fx;
	struct irdm_image_header h, orig;
	size_t size;
	uint8_t *buf;

	(void)state;
	small_fir(&fx);
	fixture_buffer(&fx, (void **)&buf, &size);
	orig = get_header(buf);

	h = orig;
	h.section_count = 0;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_EFORMAT, "section_count is 0");
	h.section_count = 33;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_EFORMAT, "section_count is 33");

	h = orig;
	h.section_table_offset = 96;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_ERANGE, "section table offset 96");
	h.section_table_offset = 0;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_ERANGE, "section table offset 0");
	h.section_table_offset = (uint32_t)(size / 64 * 64);
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_ERANGE, "outside");
	h.section_table_offset = 0xffffffc0u;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_ERANGE, "outside");
	free(buf);
	img_fixture_free(&fx);
}

/* Tamper with one table entry, reseal, and expect code. */
static void expect_entry(const uint8_t *orig, size_t size, uint32_t kind,
			 void (*edit)(struct irdm_image_section *, size_t),
			 int code, const char *needle)
{
	uint8_t *buf = img_fixture_copy(orig, size);
	unsigned i = entry_of(buf, kind);
	struct irdm_image_section s = get_entry(buf, i);

	edit(&s, size);
	put_entry(buf, i, &s);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, code, needle);
	free(buf);
}

static void e_past_end(struct irdm_image_section *s, size_t size)
{
	s->offset = (size + 64) / 64 * 64;
}

static void e_runs_past(struct irdm_image_section *s, size_t size)
{
	s->size = size - s->offset + 1;
}

static void e_wraps(struct irdm_image_section *s, size_t size)
{
	(void)size;
	s->size = UINT64_MAX - s->offset + 2; /* offset + size wraps to 1 */
}

static void e_misaligned(struct irdm_image_section *s, size_t size)
{
	(void)size;
	s->offset += 8;
}

static void e_in_table(struct irdm_image_section *s, size_t size)
{
	(void)size;
	s->offset = 64;
}

static void e_in_header(struct irdm_image_section *s, size_t size)
{
	(void)size;
	s->offset = 0;
}

static void e_elem(struct irdm_image_section *s, size_t size)
{
	(void)size;
	s->elem = 9;
}

static void e_reserved(struct irdm_image_section *s, size_t size)
{
	(void)size;
	s->reserved = 1;
}

static void e_dup_nodes(struct irdm_image_section *s, size_t size)
{
	(void)size;
	s->kind = IRDM_SEC_NODES;
}

static void e_shrink(struct irdm_image_section *s, size_t size)
{
	(void)size;
	s->size -= 4;
}

static void test_section_out_of_range(void **state)
{
	struct img_fixture fx;
	struct irdm_image_section a, b;
	size_t size;
	uint8_t *buf;

	(void)state;
	small_fir(&fx);
	fixture_buffer(&fx, (void **)&buf, &size);
	expect_entry(buf, size, IRDM_SEC_FIR, e_past_end, IRDM_ERANGE,
		     "(FIR): payload at");
	expect_entry(buf, size, IRDM_SEC_STABILITY, e_runs_past,
		     IRDM_ERANGE, "runs past the end");
	expect_entry(buf, size, IRDM_SEC_NODES, e_wraps, IRDM_ERANGE,
		     "runs past the end");
	expect_entry(buf, size, IRDM_SEC_COLUMNS, e_misaligned,
		     IRDM_ERANGE, "is not a multiple of 64");
	expect_entry(buf, size, IRDM_SEC_META, e_in_table, IRDM_ERANGE,
		     "the section table [64, 288) and section #0 (META)");
	expect_entry(buf, size, IRDM_SEC_META, e_in_header, IRDM_ERANGE,
		     "the header [0, 64) and section #0 (META) [0, 256) overlap");
	expect_entry(buf, size, IRDM_SEC_SURFACE, e_elem, IRDM_EFORMAT,
		     "unknown element type 9");
	expect_entry(buf, size, IRDM_SEC_SURFACE, e_reserved, IRDM_EFORMAT,
		     "reserved");
	/* 4 bytes fewer leave non-zero data as "padding"; the size check
	 * would name it otherwise. */
	expect_entry(buf, size, IRDM_SEC_PROVENANCE, e_shrink,
		     IRDM_EFORMAT, "padding byte");
	expect_entry(buf, size, IRDM_SEC_SURFACE, e_dup_nodes,
		     IRDM_EMISSING, "appears twice");

	/* Overlap: two payloads share bytes. */
	a = get_entry(buf, entry_of(buf, IRDM_SEC_NODES));
	b = get_entry(buf, entry_of(buf, IRDM_SEC_COLUMNS));
	b.offset = a.offset + 64;
	put_entry(buf, entry_of(buf, IRDM_SEC_COLUMNS), &b);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_ERANGE, "overlap");
	free(buf);
	img_fixture_free(&fx);
}

static void test_padding_must_be_zero(void **state)
{
	struct img_fixture fx;
	struct irdm_image_section s;
	size_t size;
	uint8_t *buf;

	(void)state;
	small_fir(&fx);
	fixture_buffer(&fx, (void **)&buf, &size);
	buf[64 + 7 * 32 + 1] = 0x5a; /* after the table of 7 */
	expect_parse(buf, size, IRDM_EFORMAT,
		     "padding byte at offset 289 is 0x5a");
	buf[64 + 7 * 32 + 1] = 0;
	s = get_entry(buf, entry_of(buf, IRDM_SEC_PROVENANCE));
	buf[s.offset + s.size] = 1; /* after a payload */
	expect_parse(buf, size, IRDM_EFORMAT, "padding");
	free(buf);
	img_fixture_free(&fx);
}

static void test_unaligned_buffer(void **state)
{
	struct img_fixture fx;
	struct irdm_image img;
	char err[256];
	size_t size;
	uint8_t *buf, *odd;

	(void)state;
	small_fir(&fx);
	fixture_buffer(&fx, (void **)&buf, &size);
	odd = malloc(size + 8);
	assert_non_null(odd);
	memcpy(odd + 4, buf, size);
	assert_int_equal(irdm_image_parse(odd + 4, size, &img, err, sizeof(err)),
			 IRDM_EINVAL);
	assert_non_null(strstr(err, "8-byte aligned"));
	assert_int_equal(irdm_image_parse(NULL, 0, &img, NULL, 0),
			 IRDM_ETRUNC);
	free(odd);
	free(buf);
	img_fixture_free(&fx);
}

/* Unknown kinds are skipped (forward compatibility) but still checked. */
static void test_unknown_kind(void **state)
{
	static const uint8_t blob[40] = { 1, 2, 3 };
	struct irdm_image_writer w;
	struct img_fixture fx;
	struct irdm_image_section s;
	size_t size;
	uint8_t *buf;
	unsigned i;

	(void)state;
	small_fir(&fx);
	irdm_iw_init(&w);
	img_fixture_add(&fx, &w);
	assert_int_equal(irdm_iw_add(&w, 0x1000, IRDM_ELEM_BYTES, blob, 40), 0);
	assert_int_equal(irdm_iw_add(&w, IRDM_SEC_CONTACT_BVH, IRDM_ELEM_U32,
				     blob, 40),
			 0);
	assert_int_equal(irdm_iw_to_buffer(&w, (void **)&buf, &size), 0);
	expect_parse(buf, size, IRDM_OK, NULL);

	i = entry_of(buf, 0x1000);
	s = get_entry(buf, i);
	buf[s.offset] ^= 1;
	expect_parse(buf, size, IRDM_ECRC, "(unknown kind) checksum");
	buf[s.offset] ^= 1;
	s.offset = size + 64;
	put_entry(buf, i, &s);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_ERANGE, "unknown kind");
	free(buf);
	img_fixture_free(&fx);
}

/* ---------------------------------------------------- semantic validation */

static void w_remove(struct irdm_image_writer *w, uint32_t kind)
{
	unsigned j = 0;

	for (unsigned i = 0; i < w->n; i++)
		if (w->sec[i].kind != kind)
			w->sec[j++] = w->sec[i];
	w->n = j;
}

static struct irdm_mode spare_modes[2];
static uint8_t spare_bytes[256];

static void w_no_meta(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_META);
}
static void w_no_prov(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_PROVENANCE);
}
static void w_no_nodes(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_NODES);
}
static void w_no_cols(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_COLUMNS);
}
static void w_no_surface(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_SURFACE);
}
static void w_no_stab(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_STABILITY);
}
static void w_no_fir(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_FIR);
}
static void w_no_modes(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_MODES);
}
static void w_no_shapes(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_MODE_SHAPES);
}
static void w_no_rigid(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_RIGID);
}
static void w_no_corr(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_STATIC_CORR);
}
static void w_no_corr_index(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_STATIC_CORR_INDEX);
}

/* A 2-column correction of one block per column, each the other's: the
 * diagonal of column 0 is missing. */
static const uint32_t corr_index_no_diag[] = { 0, 1, 2, 1, 1 };
static double corr_two_blocks[18];
static uint32_t corr_index_long[3 + 4 + 1] = { 0, 2, 4, 0, 1, 0, 1, 0 };

static void w_corr_no_diag(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_STATIC_CORR);
	w_remove(w, IRDM_SEC_STATIC_CORR_INDEX);
	irdm_iw_add(w, IRDM_SEC_STATIC_CORR, IRDM_ELEM_F64, corr_two_blocks, sizeof(corr_two_blocks));
	irdm_iw_add(w, IRDM_SEC_STATIC_CORR_INDEX, IRDM_ELEM_U32, corr_index_no_diag,
		    sizeof(corr_index_no_diag));
}

/* an index one word longer than its starts say */
static void w_corr_index_long(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_STATIC_CORR_INDEX);
	irdm_iw_add(w, IRDM_SEC_STATIC_CORR_INDEX, IRDM_ELEM_U32, corr_index_long,
		    sizeof(corr_index_long));
}

/* blocks for 2 of the index's 4 */
static void w_corr_short(struct irdm_image_writer *w)
{
	w_remove(w, IRDM_SEC_STATIC_CORR);
	irdm_iw_add(w, IRDM_SEC_STATIC_CORR, IRDM_ELEM_F64, corr_two_blocks, sizeof(corr_two_blocks));
}

static double head_blocks[4 * 2 * 9];

static void w_add_head(struct irdm_image_writer *w)
{
	for (size_t i = 0; i < sizeof(head_blocks) / sizeof(head_blocks[0]); i++)
		head_blocks[i] = (double)i / 64;
	irdm_iw_add(w, IRDM_SEC_EXACT_HEAD, IRDM_ELEM_F64, head_blocks, sizeof(head_blocks));
}

static void w_add_head_short(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_EXACT_HEAD, IRDM_ELEM_F64, head_blocks, sizeof(head_blocks) / 2);
}

static void w_add_head_nan(struct irdm_image_writer *w)
{
	w_add_head(w);
	head_blocks[40] = NAN;
}

static void w_add_scales(struct irdm_image_writer *w);

/* The head by pairs (2.5) of the modal fixture's 2 x 2 blocks: runs for
 * (0, 0), (0, 1) and (1, 1); block (1, 0) reads (0, 1)'s transposed. */
static const uint32_t pairs_ok[4] = { 0, 1, 1 | IRDM_HEAD_TRANSPOSED, 2 };
static const uint32_t pairs_skip[4] = { 0, 2, 2 | IRDM_HEAD_TRANSPOSED, 3 };
static const uint32_t pairs_upright[4] = { 0, 1, 1, 2 };
static const uint32_t pairs_other[4] = { 0, 1, 0 | IRDM_HEAD_TRANSPOSED, 2 };

static void w_add_pairs_runs(struct irdm_image_writer *w, const uint32_t *index)
{
	for (size_t i = 0; i < sizeof(head_blocks) / sizeof(head_blocks[0]); i++)
		head_blocks[i] = (double)i / 64;
	irdm_iw_add(w, IRDM_SEC_EXACT_HEAD, IRDM_ELEM_F64, head_blocks, sizeof(head_blocks) * 3 / 4);
	if (index)
		irdm_iw_add(w, IRDM_SEC_EXACT_HEAD_INDEX, IRDM_ELEM_U32, index, 4 * sizeof(uint32_t));
}

static void w_add_pairs(struct irdm_image_writer *w)
{
	w_add_pairs_runs(w, pairs_ok);
}

static void w_add_pairs_skip(struct irdm_image_writer *w)
{
	w_add_pairs_runs(w, pairs_skip);
}

static void w_add_pairs_upright(struct irdm_image_writer *w)
{
	w_add_pairs_runs(w, pairs_upright);
}

static void w_add_pairs_other(struct irdm_image_writer *w)
{
	w_add_pairs_runs(w, pairs_other);
}

static void w_add_pairs_no_index(struct irdm_image_writer *w)
{
	w_add_pairs_runs(w, NULL);
}

/* every block's run, as without pairs, but the index too */
static void w_add_pairs_whole(struct irdm_image_writer *w)
{
	w_add_head(w);
	irdm_iw_add(w, IRDM_SEC_EXACT_HEAD_INDEX, IRDM_ELEM_U32, pairs_ok, sizeof(pairs_ok));
}

static void w_add_pairs_scales(struct irdm_image_writer *w)
{
	w_add_pairs(w);
	w_add_scales(w);
}

/* an index in a FIR image */
static void w_add_corr_index(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_STATIC_CORR_INDEX, IRDM_ELEM_U32, corr_index_no_diag,
		    sizeof(corr_index_no_diag));
}

static void w_add_modes(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_MODES, IRDM_ELEM_BYTES, spare_modes,
		    sizeof(spare_modes));
}

static void w_add_rigid(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_RIGID, IRDM_ELEM_BYTES, spare_bytes, 128);
}

static void w_add_fir(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_FIR, IRDM_ELEM_F64, spare_bytes, 64);
}

static void w_meta_short(struct irdm_image_writer *w)
{
	w->sec[0].size = 248; /* META is added first */
}

static void w_surface_short(struct irdm_image_writer *w)
{
	for (unsigned i = 0; i < w->n; i++)
		if (w->sec[i].kind == IRDM_SEC_SURFACE)
			w->sec[i].size -= 12;
}

static void w_modes_short(struct irdm_image_writer *w)
{
	for (unsigned i = 0; i < w->n; i++)
		if (w->sec[i].kind == IRDM_SEC_MODES)
			w->sec[i].size -= 64;
}

/* The element type section kind declares in its table entry. */
static void w_set_elem(struct irdm_image_writer *w, uint32_t kind, uint32_t elem)
{
	for (unsigned i = 0; i < w->n; i++)
		if (w->sec[i].kind == kind)
			w->sec[i].elem = elem;
}

static void w_fir_elem(struct irdm_image_writer *w)
{
	w_set_elem(w, IRDM_SEC_FIR, IRDM_ELEM_U32);
}

#define FX(name, stmt) \
	static void name(struct img_fixture *fx) \
	{ \
		stmt; \
	}

FX(m_dt_zero, fx->meta.dt_s = 0)
FX(m_dt_big, fx->meta.dt_s = 1.5)
FX(m_dt_tiny, fx->meta.dt_s = 1e-300)
FX(m_dt_nan, fx->meta.dt_s = NAN)
FX(m_dt_one, fx->meta.dt_s = 1)
FX(m_young, fx->meta.young_pa = 0)
FX(m_poisson_half, fx->meta.poisson = 0.5)
FX(m_poisson_m1, fx->meta.poisson = -1)
FX(m_poisson_auxetic, fx->meta.poisson = -0.9)
FX(m_density, fx->meta.density_kg_m3 = -110)
FX(m_rayleigh_inf, fx->meta.rayleigh_a_per_s = INFINITY)
FX(m_first_hz_nan, fx->meta.first_elastic_hz = NAN)
FX(m_repr, fx->meta.representation = 3)
FX(m_prec_u32, fx->meta.precision = IRDM_ELEM_U32)
FX(m_no_nodes, fx->meta.n_nodes = 0)
FX(m_cols_gt_nodes, fx->meta.n_cols = fx->meta.n_nodes + 1)
FX(m_no_cols, fx->meta.n_cols = 0)
FX(m_fir_len0, fx->meta.fir_length = 0)
FX(m_fir_len5, fx->meta.fir_length = 5)
FX(m_fir_modes, fx->meta.n_modes = 1)
FX(m_fir_corr_flag, fx->meta.flags |= IRDM_META_STATIC_CORR)
FX(m_unknown_flag, fx->meta.flags |= 1u << 9)
FX(m_fir_exact, fx->meta.fir_exact = 1)
FX(m_fir_window_flag, fx->meta.flags |= IRDM_META_FIR_TAIL_WINDOW)
/* format 2.3's measured error: without its flag, or not a number */
FX(m_error_no_flag, fx->meta.measured_error = 0.5f)
FX(m_error_nan, (fx->meta.flags |= IRDM_META_ERROR_MEASURED, fx->meta.measured_error = NAN))
FX(m_error_neg, (fx->meta.flags |= IRDM_META_ERROR_MEASURED, fx->meta.measured_error = -1e-3f))
FX(m_error_ok, (fx->meta.flags |= IRDM_META_ERROR_MEASURED, fx->meta.measured_error = 2.5e-4f))
/* the hybrid's head (format 2.1): 2 samples of the modal fixture's 4 blocks */
FX(m_head2, (fx->meta.flags |= IRDM_META_EXACT_HEAD, fx->meta.head_samples = 2))
FX(m_head_samples_only, fx->meta.head_samples = 2)
FX(m_head_no_corr, (fx->meta.flags = (fx->meta.flags & ~IRDM_META_STATIC_CORR) | IRDM_META_EXACT_HEAD,
		    fx->meta.head_samples = 2))
FX(m_head_big, (fx->meta.flags |= IRDM_META_EXACT_HEAD, fx->meta.head_samples = IRDM_HEAD_SAMPLES_MAX + 1))
/* the head by pairs (format 2.5) */
FX(m_pairs, (fx->meta.flags |= IRDM_META_EXACT_HEAD | IRDM_META_HEAD_PAIRS, fx->meta.head_samples = 2))
FX(m_pairs_no_head, fx->meta.flags |= IRDM_META_HEAD_PAIRS)
FX(m_pairs_scale, (fx->meta.flags |= IRDM_META_EXACT_HEAD | IRDM_META_HEAD_PAIRS | IRDM_META_COLUMN_SCALE,
		   fx->meta.head_samples = 2))
FX(m_tool_nul, memset(fx->meta.tool_version, 'x', 32))
FX(m_name_nul, memset(fx->meta.mesh_name, 'x', 64))
FX(m_node_nan, fx->nodes[3].pos_m[1] = NAN)
FX(m_mesh_node, fx->nodes[2].mesh_node = fx->meta.mesh_nodes)
FX(m_col_range, fx->columns[1] = fx->meta.n_nodes)
FX(m_col_dup, fx->columns[1] = fx->columns[0])
FX(m_tri_range, fx->tris[7] = fx->meta.n_nodes)
FX(m_fir_nan, ((float *)fx->fir)[100] = NAN)
FX(m_fir_inf, ((float *)fx->fir)[fx->fir_bytes / 4 - 1] = -INFINITY)
FX(m_stab_nan, fx->stability[1].spectral_radius = NAN)
FX(m_stab_neg, fx->stability[0].spectral_radius = -0.5f)
FX(m_stab_flag, fx->stability[1].flags |= IRDM_STAB_STABLE)
FX(m_prov_nul, fx->provenance[10] = '\0')
/* the table says unstable (1.0317), the meta's copy 0.5: checksums all valid */
static void m_radius_forged(struct img_fixture *fx)
{
	for (uint32_t c = 0; c < fx->meta.n_cols; c++) {
		fx->stability[c].spectral_radius = 1.0317f;
		fx->stability[c].flags = 0;
	}
	fx->meta.max_spectral_radius = 0.5;
}

static void m_unstable_flag(struct img_fixture *fx)
{
	for (uint32_t c = 0; c < fx->meta.n_cols; c++) {
		fx->stability[c].spectral_radius = 0.5f;
		fx->stability[c].flags = 0;
	}
	fx->meta.max_spectral_radius = 0.5;
}

static void m_prov_rayleigh(struct img_fixture *fx)
{
	fx->meta.rayleigh_a_per_s = 2;
	fx->provenance_len += (size_t)snprintf(fx->provenance + fx->provenance_len,
					       sizeof(fx->provenance) - fx->provenance_len,
					       "rayleigh_a_per_s=3\n");
}

/* The two-contact figure: a number >= 0, or the image is wrong. */
static void prov_two_contacts(struct img_fixture *fx, const char *v)
{
	fx->provenance_len += (size_t)snprintf(fx->provenance + fx->provenance_len,
					       sizeof(fx->provenance) - fx->provenance_len,
					       "two_contacts_error=%s\n", v);
}

FX(m_pairs_text, prov_two_contacts(fx, "0.01x"))
FX(m_pairs_neg, prov_two_contacts(fx, "-0.002"))
FX(m_pairs_inf, prov_two_contacts(fx, "inf"))
FX(m_pairs_empty, prov_two_contacts(fx, ""))
FX(m_pairs_twice, (prov_two_contacts(fx, "0.5"), prov_two_contacts(fx, "0.001")))
FX(m_prov_tool, snprintf(fx->meta.tool_version, sizeof(fx->meta.tool_version), "irdm-test 0.2"))
FX(m_floating, fx->meta.flags |= IRDM_META_FLOATING)
FX(m_mass, fx->rigid.mass_kg = 0)
FX(m_inertia, fx->rigid.inertia_kg_m2[4] = NAN)
FX(m_rigid_res, fx->rigid.reserved[2] = 1)
FX(m_no_corr_flag, fx->meta.flags &= ~(uint32_t)IRDM_META_STATIC_CORR)
FX(m_grounded, fx->meta.flags &= ~(uint32_t)IRDM_META_FLOATING)
FX(m_modes0, fx->meta.n_modes = 0)
FX(m_modal_fir_len, fx->meta.fir_length = 1)
FX(m_zeta_neg, fx->modes[1].zeta = -0.05)
FX(m_omega_nan, fx->modes[0].omega_rad_s = NAN)
FX(m_omega_neg, fx->modes[2].omega_rad_s = -1)
FX(m_a_inf, fx->modes[2].a[3] = INFINITY)
FX(m_b_nan, fx->modes[0].b[1] = NAN)
FX(m_shape_nan, ((double *)fx->mode_shapes)[7] = NAN)
FX(m_corr_inf, ((double *)fx->static_corr)[29] = INFINITY)
/* index [0 2 4 | 0 1 | 0 1] of the fixture's 2 columns */
FX(m_corr_start0, fx->corr_index[0] = 1)
FX(m_corr_start_down, fx->corr_index[1] = 5)
FX(m_corr_row_range, fx->corr_index[3 + 1] = 2)
FX(m_corr_row_order, (fx->corr_index[3 + 2] = 1, fx->corr_index[3 + 3] = 0))
FX(m_corr_row_repeat, fx->corr_index[3 + 1] = 0)
FX(m_corr_blocks_big, fx->corr_index[2] = 0x40000000u)

/* STATIC_CORR_LOWRANK of rank 2 on the fixture's 2 columns (6 DoFs): the
 * header, then 2 lambdas and 6 x 2 U values, f64 */
static struct irdm_corr_lowrank_header *with_lowrank(struct img_fixture *fx)
{
	assert_int_equal(img_fixture_lowrank(fx, 2), 0);
	return fx->corr_lowrank;
}

static double *lowrank_values(struct img_fixture *fx)
{
	return (double *)((uint8_t *)with_lowrank(fx) + sizeof(struct irdm_corr_lowrank_header));
}

FX(m_lr_rank0, with_lowrank(fx)->rank = 0)
FX(m_lr_rank_big, with_lowrank(fx)->rank = 7)
FX(m_lr_rank_size, with_lowrank(fx)->rank = 1)
FX(m_lr_reserved, with_lowrank(fx)->reserved[1] = 1)
FX(m_lr_lambda_nan, lowrank_values(fx)[1] = NAN)
FX(m_lr_u_inf, lowrank_values(fx)[2 + 2 * (3 + 2)] = INFINITY) /* U[5][0] */
FX(m_lr_short, (with_lowrank(fx), fx->lowrank_bytes = 8))
FX(m_lr_long, (with_lowrank(fx), fx->lowrank_bytes -= 8))
/* The modal fixture without its static correction (flag and sections). */
static void drop_corr(struct img_fixture *fx)
{
	fx->meta.flags &= ~(uint32_t)IRDM_META_STATIC_CORR;
	free(fx->static_corr);
	free(fx->corr_index);
	fx->static_corr = NULL;
	fx->corr_index = NULL;
}

/* the far field without the correction it belongs to */
FX(m_lr_no_corr, (with_lowrank(fx), drop_corr(fx)))

static const uint8_t lowrank_bytes[16 + 8 * 2 * 7] = { 2 }; /* rank 2, zeros */

static void w_add_lowrank(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_STATIC_CORR_LOWRANK, IRDM_ELEM_BYTES, lowrank_bytes,
		    sizeof(lowrank_bytes));
}

static void w_lowrank_f64(struct irdm_image_writer *w)
{
	w_set_elem(w, IRDM_SEC_STATIC_CORR_LOWRANK, IRDM_ELEM_F64);
}

static void m_lr_elem(struct img_fixture *fx)
{
	with_lowrank(fx);
}

/* STATIC_CORR_CLUSTERS on the fixture's 2 columns, f64: 2 clusters of one
 * column (members [1 0], col_pos [1 0]), self pairs their upper triangles
 * (6 values each), the cross pair of rank 2 (U, V: 6 x 2 values); built
 * once per case so that several edits add up.  Bytes: header 0..32, start
 * 32..44, members 44..52, col_pos 52..60, padding 60..64, pairs 64..112,
 * values 112..304. */
static uint8_t *clusters(struct img_fixture *fx)
{
	if (!fx->corr_clusters)
		assert_int_equal(img_fixture_clusters(fx, 2, 2, NULL), 0);
	return fx->corr_clusters;
}

static struct irdm_corr_clusters_header *cl_hdr(struct img_fixture *fx)
{
	return (struct irdm_corr_clusters_header *)clusters(fx);
}

/* start[0..2], members[3..4], col_pos[5..6] */
static uint32_t *cl_tables(struct img_fixture *fx)
{
	return (uint32_t *)(clusters(fx) + sizeof(struct irdm_corr_clusters_header));
}

static struct irdm_corr_pair *cl_pairs(struct img_fixture *fx)
{
	return (struct irdm_corr_pair *)(clusters(fx) + img_fixture_clusters_tables(2, 2));
}

/* pair (0, 0) at 0..8, (0, 1) at 9..20, (1, 1) at 21..29 */
static double *cl_values(struct img_fixture *fx)
{
	return (double *)(cl_pairs(fx) + 3);
}

FX(m_cl_ok, clusters(fx))
FX(m_cl_short, (clusters(fx), fx->clusters_bytes = 24))
FX(m_cl_long, (clusters(fx), fx->clusters_bytes -= 8))
FX(m_cl_none, cl_hdr(fx)->n_clusters = 0)
FX(m_cl_many, cl_hdr(fx)->n_clusters = 3)
FX(m_cl_max_rank, cl_hdr(fx)->max_rank = IRDM_CORR_LOWRANK_MAX + 1)
FX(m_cl_reserved, cl_hdr(fx)->reserved[3] = 1)
FX(m_cl_n_values, cl_hdr(fx)->n_values = 25)
/* 8 n_values wraps to the right size: only the overflow guard catches it */
FX(m_cl_n_values_wrap, cl_hdr(fx)->n_values = (UINT64_MAX / 8 + 1) + 30)
FX(m_cl_start0, cl_tables(fx)[0] = 1)
FX(m_cl_start_end, cl_tables(fx)[2] = 1)
FX(m_cl_empty, cl_tables(fx)[1] = 0)
FX(m_cl_reversed, cl_tables(fx)[1] = 3)
FX(m_cl_member_range, cl_tables(fx)[3] = 2)
FX(m_cl_col_pos, cl_tables(fx)[5 + 1] = 1)
FX(m_cl_member_repeat, cl_tables(fx)[4] = 1)
FX(m_cl_padding, clusters(fx)[60] = 1)
FX(m_cl_self_rank, cl_pairs(fx)[0].rank = 2)
FX(m_cl_self_rank_last, cl_pairs(fx)[2].rank = 0)
FX(m_cl_rank_size, (cl_pairs(fx)[1].rank = 4, cl_hdr(fx)->max_rank = 4))
FX(m_cl_rank_max, cl_hdr(fx)->max_rank = 1)
FX(m_cl_pair_reserved, cl_pairs(fx)[1].reserved = 1)
FX(m_cl_offset_gap, cl_pairs(fx)[1].offset = 10)
FX(m_cl_pairs_short, (cl_pairs(fx)[1].rank = 1, cl_pairs(fx)[2].offset = 6 + 6))
FX(m_cl_pairs_long, (cl_pairs(fx)[1].rank = 3, cl_hdr(fx)->max_rank = 3, cl_pairs(fx)[2].offset = 6 + 18))
FX(m_cl_nan, cl_values(fx)[3] = NAN)
FX(m_cl_inf, cl_values(fx)[23] = -INFINITY)
/* the clusters without the correction they belong to */
FX(m_cl_no_corr, (clusters(fx), drop_corr(fx)))

static const uint8_t clusters_bytes[32] = { 1 }; /* 1 cluster, tables missing */

static void w_add_clusters(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_STATIC_CORR_CLUSTERS, IRDM_ELEM_BYTES, clusters_bytes,
		    sizeof(clusters_bytes));
}

static void w_clusters_f64(struct irdm_image_writer *w)
{
	w_set_elem(w, IRDM_SEC_STATIC_CORR_CLUSTERS, IRDM_ELEM_F64);
}

/* COLUMN_SCALE (format 2.4) on the fixture's 2 columns */
FX(m_scale, fx->meta.flags |= IRDM_META_COLUMN_SCALE)

static const float scales_ok[2] = { 0.25f, 0x1p-30f };
static const float scales_three[2] = { 0.25f, 3.0f };
static const float scales_zero[2] = { 0.0f, 1.0f };
static const float scales_sub[2] = { 1.0f, 0x1p-140f };

static void w_add_scales(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_COLUMN_SCALE, IRDM_ELEM_F32, scales_ok, sizeof(scales_ok));
}

static void w_add_scales_three(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_COLUMN_SCALE, IRDM_ELEM_F32, scales_three, sizeof(scales_three));
}

static void w_add_scales_zero(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_COLUMN_SCALE, IRDM_ELEM_F32, scales_zero, sizeof(scales_zero));
}

static void w_add_scales_sub(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_COLUMN_SCALE, IRDM_ELEM_F32, scales_sub, sizeof(scales_sub));
}

static void w_add_scales_short(struct irdm_image_writer *w)
{
	irdm_iw_add(w, IRDM_SEC_COLUMN_SCALE, IRDM_ELEM_F32, scales_ok, sizeof(float));
}

enum base { FIR,
	    MODAL };

struct sem_case {
	const char *name;
	enum base base;
	void (*fx_edit)(struct img_fixture *);
	void (*w_edit)(struct irdm_image_writer *);
	int code;
	const char *needle;
};

static const struct sem_case sem_cases[] = {
	{ "dt 0", FIR, m_dt_zero, NULL, IRDM_EFORMAT, "dt_s is 0 s" },
	{ "dt 1.5", FIR, m_dt_big, NULL, IRDM_EFORMAT, "dt_s is 1.5" },
	{ "dt 1e-300", FIR, m_dt_tiny, NULL, IRDM_EFORMAT, "dt_s is 1e-300 s, must be in [1e-06, 1]" },
	{ "dt NaN", FIR, m_dt_nan, NULL, IRDM_EFORMAT, "dt_s is not finite" },
	{ "dt 1", FIR, m_dt_one, NULL, IRDM_OK, NULL },
	{ "young", FIR, m_young, NULL, IRDM_EFORMAT, "young_pa" },
	{ "poisson 0.5", FIR, m_poisson_half, NULL, IRDM_EFORMAT, "poisson is 0.5" },
	{ "poisson -1", FIR, m_poisson_m1, NULL, IRDM_EFORMAT, "poisson is -1" },
	{ "poisson -0.9", FIR, m_poisson_auxetic, NULL, IRDM_OK, NULL },
	{ "density", FIR, m_density, NULL, IRDM_EFORMAT, "density_kg_m3 is -110" },
	{ "rayleigh inf", FIR, m_rayleigh_inf, NULL, IRDM_EFORMAT, "rayleigh_a_per_s" },
	{ "first hz", FIR, m_first_hz_nan, NULL, IRDM_EFORMAT, "first_elastic_hz" },
	{ "repr", FIR, m_repr, NULL, IRDM_EFORMAT, "representation is 3" },
	{ "precision", FIR, m_prec_u32, NULL, IRDM_EFORMAT, "precision is 4" },
	{ "n_nodes 0", FIR, m_no_nodes, NULL, IRDM_EFORMAT, "n_nodes 0" },
	{ "n_cols > n_nodes", FIR, m_cols_gt_nodes, NULL, IRDM_EFORMAT, "n_cols 7" },
	{ "n_cols 0", FIR, m_no_cols, NULL, IRDM_EFORMAT, "n_cols 0" },
	{ "T 0", FIR, m_fir_len0, NULL, IRDM_EFORMAT, "fir_length 0" },
	{ "T mismatch", FIR, m_fir_len5, NULL, IRDM_EFORMAT, "section FIR has 1728 bytes, expected 2160" },
	{ "FIR n_modes", FIR, m_fir_modes, NULL, IRDM_EFORMAT, "n_modes 1" },
	{ "FIR corr flag", FIR, m_fir_corr_flag, NULL, IRDM_EFORMAT, "STATIC_CORR" },
	{ "meta flag", FIR, m_unknown_flag, NULL, IRDM_EFORMAT, "unknown flags" },
	{ "meta fir_exact without its flag", FIR, m_fir_exact, NULL, IRDM_EFORMAT, "fir_exact 1" },
	{ "meta tail window without fir_exact", FIR, m_fir_window_flag, NULL, IRDM_EFORMAT,
	  "FIR_TAIL_WINDOW set" },
	{ "meta error without its flag", FIR, m_error_no_flag, NULL, IRDM_EFORMAT,
	  "measured_error is 0.5 without the ERROR_MEASURED flag" },
	{ "meta error NaN", FIR, m_error_nan, NULL, IRDM_EFORMAT, "measured_error is nan, must be finite" },
	{ "meta error negative", FIR, m_error_neg, NULL, IRDM_EFORMAT, "measured_error is -0.001" },
	{ "meta error measured", FIR, m_error_ok, NULL, IRDM_OK, NULL },
	{ "tool_version", FIR, m_tool_nul, NULL, IRDM_EFORMAT, "NUL-terminated" },
	{ "mesh_name", FIR, m_name_nul, NULL, IRDM_EFORMAT, "NUL-terminated" },
	{ "node NaN", FIR, m_node_nan, NULL, IRDM_EFORMAT, "node 3 has a non-finite position" },
	{ "mesh_node", FIR, m_mesh_node, NULL, IRDM_EFORMAT, "mesh_node 12 >= mesh_nodes 12" },
	{ "column range", FIR, m_col_range, NULL, IRDM_EFORMAT, "column 1 names node 6" },
	{ "column dup", FIR, m_col_dup, NULL, IRDM_EFORMAT, "column 1 repeats node 5" },
	{ "triangle", FIR, m_tri_range, NULL, IRDM_EFORMAT, "triangle 2 names node 6" },
	{ "n_tris", FIR, NULL, w_surface_short, IRDM_EFORMAT, "section SURFACE has 36 bytes, expected 48 (n_tris x 3 x 4)" },
	{ "FIR NaN", FIR, m_fir_nan, NULL, IRDM_EFORMAT, "FIR element 100 (column 0, row 2, sample 3, entry 0,1) is not finite" },
	{ "FIR inf", FIR, m_fir_inf, NULL, IRDM_EFORMAT, "FIR element 431 (column 1, row 5, sample 3, entry 2,2)" },
	{ "stability NaN", FIR, m_stab_nan, NULL, IRDM_EFORMAT, "column 1: spectral radius" },
	{ "stability < 0", FIR, m_stab_neg, NULL, IRDM_EFORMAT, "spectral radius -0.5" },
	{ "stable flag", FIR, m_stab_flag, NULL, IRDM_EFORMAT, "flagged stable" },
	{ "meta radius forged", FIR, m_radius_forged, NULL, IRDM_EFORMAT,
	  "meta max_spectral_radius 0.5 disagrees with the STABILITY table, whose largest radius is 1.03170002 (column 0)" },
	{ "unstable flag", FIR, m_unstable_flag, NULL, IRDM_EFORMAT,
	  "column 0 is flagged unstable with spectral radius 0.5" },
	{ "provenance copy", FIR, m_prov_rayleigh, NULL, IRDM_EFORMAT,
	  "PROVENANCE rayleigh_a_per_s=3 disagrees with meta's 2" },
	{ "provenance tool", FIR, m_prov_tool, NULL, IRDM_EFORMAT,
	  "PROVENANCE tool=irdm-test 0.1 disagrees with meta's tool_version 'irdm-test 0.2'" },
	{ "provenance NUL", FIR, m_prov_nul, NULL, IRDM_EFORMAT, "NUL byte at offset 10" },
	{ "two contacts text", FIR, m_pairs_text, NULL, IRDM_EFORMAT,
	  "PROVENANCE two_contacts_error=0.01x is not a finite number >= 0" },
	{ "two contacts negative", FIR, m_pairs_neg, NULL, IRDM_EFORMAT, "two_contacts_error=-0.002 is not" },
	{ "two contacts inf", FIR, m_pairs_inf, NULL, IRDM_EFORMAT, "two_contacts_error=inf is not" },
	{ "two contacts empty", FIR, m_pairs_empty, NULL, IRDM_EFORMAT, "two_contacts_error= is not" },
	{ "two contacts twice", FIR, m_pairs_twice, NULL, IRDM_EFORMAT,
	  "PROVENANCE has two_contacts_error 2 times" },
	{ "no META", FIR, NULL, w_no_meta, IRDM_EMISSING, "META is missing" },
	{ "no PROVENANCE", FIR, NULL, w_no_prov, IRDM_EMISSING, "PROVENANCE is missing" },
	{ "no NODES", FIR, NULL, w_no_nodes, IRDM_EMISSING, "NODES is missing" },
	{ "no COLUMNS", FIR, NULL, w_no_cols, IRDM_EMISSING, "COLUMNS is missing" },
	{ "no SURFACE", FIR, NULL, w_no_surface, IRDM_EMISSING, "SURFACE is missing" },
	{ "no STABILITY", FIR, NULL, w_no_stab, IRDM_EMISSING, "STABILITY is missing" },
	{ "no FIR", FIR, NULL, w_no_fir, IRDM_EMISSING, "FIR is missing" },
	{ "FIR + MODES", FIR, NULL, w_add_modes, IRDM_EFORMAT, "MODES must not be present (FIR image)" },
	{ "grounded + RIGID", FIR, NULL, w_add_rigid, IRDM_EFORMAT, "RIGID must not be present (meta flags say grounded)" },
	{ "floating, no RIGID", FIR, m_floating, w_no_rigid, IRDM_EMISSING, "RIGID is missing" },
	{ "META short", FIR, NULL, w_meta_short, IRDM_EFORMAT, "META has 248 bytes" },
	{ "FIR elem", FIR, NULL, w_fir_elem, IRDM_EFORMAT, "FIR has element type U32, expected F32" },
	{ "modal ok", MODAL, NULL, NULL, IRDM_OK, NULL },
	{ "modal no RIGID", MODAL, NULL, w_no_rigid, IRDM_EMISSING, "RIGID is missing (meta flags say floating)" },
	{ "mass 0", MODAL, m_mass, NULL, IRDM_EFORMAT, "mass_kg is 0" },
	{ "inertia", MODAL, m_inertia, NULL, IRDM_EFORMAT, "inertia_kg_m2[4]" },
	{ "rigid reserved", MODAL, m_rigid_res, NULL, IRDM_EFORMAT, "rigid reserved" },
	{ "grounded modal + RIGID", MODAL, m_grounded, w_add_rigid, IRDM_EFORMAT, "RIGID must not be present" },
	{ "no STATIC_CORR", MODAL, NULL, w_no_corr, IRDM_EMISSING, "STATIC_CORR is missing" },
	{ "STATIC_CORR unflagged", MODAL, m_no_corr_flag, NULL, IRDM_EFORMAT, "STATIC_CORR must not be present" },
	{ "n_modes 0", MODAL, m_modes0, NULL, IRDM_EFORMAT, "n_modes 0" },
	{ "modal T", MODAL, m_modal_fir_len, NULL, IRDM_EFORMAT, "fir_length 1" },
	{ "MODES short", MODAL, NULL, w_modes_short, IRDM_EFORMAT, "section MODES has 128 bytes, expected 192 (n_modes x 64)" },
	{ "zeta < 0", MODAL, m_zeta_neg, NULL, IRDM_EFORMAT, "mode 1" },
	{ "omega NaN", MODAL, m_omega_nan, NULL, IRDM_EFORMAT, "mode 0" },
	{ "omega < 0", MODAL, m_omega_neg, NULL, IRDM_EFORMAT, "mode 2: omega -1" },
	{ "A inf", MODAL, m_a_inf, NULL, IRDM_EFORMAT, "mode 2" },
	{ "b NaN", MODAL, m_b_nan, NULL, IRDM_EFORMAT, "mode 0" },
	{ "shape NaN", MODAL, m_shape_nan, NULL, IRDM_EFORMAT, "MODE_SHAPES element 7 is not finite" },
	{ "corr inf", MODAL, m_corr_inf, NULL, IRDM_EFORMAT, "STATIC_CORR element 29 is not finite" },
	{ "no STATIC_CORR_INDEX", MODAL, NULL, w_no_corr_index, IRDM_EMISSING, "STATIC_CORR_INDEX is missing" },
	{ "corr start 0", MODAL, m_corr_start0, NULL, IRDM_EFORMAT, "start of column 0 is 1, not 0" },
	{ "corr starts down", MODAL, m_corr_start_down, NULL, IRDM_EFORMAT, "start of column 2 (4) is below column 1's (5)" },
	{ "corr row range", MODAL, m_corr_row_range, NULL, IRDM_EFORMAT, "column 0 block 1: row 2 >= n_cols 2" },
	{ "corr row order", MODAL, m_corr_row_order, NULL, IRDM_EFORMAT, "column 1: rows not strictly increasing at block 3" },
	{ "corr row repeat", MODAL, m_corr_row_repeat, NULL, IRDM_EFORMAT, "column 0: rows not strictly increasing at block 1" },
	{ "corr no diagonal", MODAL, NULL, w_corr_no_diag, IRDM_EFORMAT, "column 0 lacks its diagonal block" },
	{ "corr index long", MODAL, NULL, w_corr_index_long, IRDM_EFORMAT, "STATIC_CORR_INDEX has 32 bytes, expected 28" },
	{ "corr index vs size", MODAL, m_corr_blocks_big, NULL, IRDM_EFORMAT, "STATIC_CORR_INDEX has 28 bytes, expected 4294967308" },
	{ "corr blocks short", MODAL, NULL, w_corr_short, IRDM_EFORMAT, "section STATIC_CORR has 144 bytes, expected 288" },
	{ "FIR + STATIC_CORR_INDEX", FIR, NULL, w_add_corr_index, IRDM_EFORMAT, "STATIC_CORR_INDEX must not be present (FIR image)" },
	{ "head", MODAL, m_head2, w_add_head, IRDM_OK, NULL },
	{ "head missing", MODAL, m_head2, NULL, IRDM_EMISSING, "EXACT_HEAD is missing" },
	{ "head without its flag", MODAL, NULL, w_add_head, IRDM_EFORMAT, "EXACT_HEAD must not be present" },
	{ "head_samples without the flag", MODAL, m_head_samples_only, NULL, IRDM_EFORMAT, "head_samples 2, EXACT_HEAD clear" },
	{ "head without STATIC_CORR", MODAL, m_head_no_corr, NULL, IRDM_EFORMAT, "STATIC_CORR clear" },
	{ "head too long", MODAL, m_head_big, NULL, IRDM_EFORMAT, "head_samples 8193" },
	{ "head short", MODAL, m_head2, w_add_head_short, IRDM_EFORMAT, "section EXACT_HEAD has 288 bytes, expected 576" },
	{ "head NaN", MODAL, m_head2, w_add_head_nan, IRDM_EFORMAT, "EXACT_HEAD element 40 is not finite" },
	{ "FIR + head", FIR, NULL, w_add_head, IRDM_EFORMAT, "EXACT_HEAD must not be present (FIR image)" },
	{ "head by pairs", MODAL, m_pairs, w_add_pairs, IRDM_OK, NULL },
	{ "head pairs, no index", MODAL, m_pairs, w_add_pairs_no_index, IRDM_EMISSING, "EXACT_HEAD_INDEX is missing" },
	{ "head index without the flag", MODAL, m_head2, w_add_pairs_whole, IRDM_EFORMAT, "EXACT_HEAD_INDEX must not be present (meta flags lack HEAD_PAIRS)" },
	{ "head pairs without a head", MODAL, m_pairs_no_head, NULL, IRDM_EFORMAT, "HEAD_PAIRS without EXACT_HEAD" },
	{ "head pairs, column scales", MODAL, m_pairs_scale, w_add_pairs_scales, IRDM_EFORMAT, "both HEAD_PAIRS and COLUMN_SCALE" },
	{ "head pairs, a run skipped", MODAL, m_pairs, w_add_pairs_skip, IRDM_EFORMAT, "EXACT_HEAD_INDEX entry 1 (column 0, row 1) is 0x2, expected 1 (the next stored run)" },
	{ "head pairs, mirror upright", MODAL, m_pairs, w_add_pairs_upright, IRDM_EFORMAT, "EXACT_HEAD_INDEX entry 2 (column 1, row 0) is 0x1, expected its mirror's run 1 transposed" },
	{ "head pairs, another's run", MODAL, m_pairs, w_add_pairs_other, IRDM_EFORMAT, "EXACT_HEAD_INDEX entry 2 (column 1, row 0) is 0x80000000, expected its mirror's run 1 transposed" },
	{ "head pairs, every block's run", MODAL, m_pairs, w_add_pairs_whole, IRDM_EFORMAT, "section EXACT_HEAD has 576 bytes, expected 432 (runs in EXACT_HEAD_INDEX x head_samples x 9 x 8)" },
	{ "column scales", FIR, m_scale, w_add_scales, IRDM_OK, NULL },
	{ "column scales, modal", MODAL, m_scale, w_add_scales, IRDM_OK, NULL },
	{ "column scales missing", FIR, m_scale, NULL, IRDM_EMISSING, "COLUMN_SCALE is missing" },
	{ "column scales without the flag", FIR, NULL, w_add_scales, IRDM_EFORMAT, "COLUMN_SCALE must not be present" },
	{ "column scale 3", FIR, m_scale, w_add_scales_three, IRDM_EFORMAT, "column 1: scale 3 is not a normal power of two" },
	{ "column scale 0", FIR, m_scale, w_add_scales_zero, IRDM_EFORMAT, "column 0: scale 0 is not a normal power of two" },
	{ "column scale subnormal", FIR, m_scale, w_add_scales_sub, IRDM_EFORMAT, "column 1: scale 7.17465e-43 is not a normal power of two" },
	{ "column scales short", FIR, m_scale, w_add_scales_short, IRDM_EFORMAT, "section COLUMN_SCALE has 4 bytes, expected 8" },
	{ "no MODES", MODAL, NULL, w_no_modes, IRDM_EMISSING, "MODES is missing" },
	{ "no MODE_SHAPES", MODAL, NULL, w_no_shapes, IRDM_EMISSING, "MODE_SHAPES is missing" },
	{ "modal + FIR", MODAL, NULL, w_add_fir, IRDM_EFORMAT, "FIR must not be present (modal image)" },
	{ "lowrank rank 0", MODAL, m_lr_rank0, NULL, IRDM_EFORMAT, "STATIC_CORR_LOWRANK: rank 0 is not in 1..6 (3 n_cols, at most 1024)" },
	{ "lowrank rank > 3 n_cols", MODAL, m_lr_rank_big, NULL, IRDM_EFORMAT, "STATIC_CORR_LOWRANK: rank 7 is not in 1..6" },
	{ "lowrank rank vs size", MODAL, m_lr_rank_size, NULL, IRDM_EFORMAT, "section STATIC_CORR_LOWRANK has 128 bytes, expected 72 (16 + rank 1 x (1 + 3 n_cols) x 8)" },
	{ "lowrank long", MODAL, m_lr_long, NULL, IRDM_EFORMAT, "section STATIC_CORR_LOWRANK has 120 bytes, expected 128" },
	{ "lowrank short", MODAL, m_lr_short, NULL, IRDM_EFORMAT, "section STATIC_CORR_LOWRANK has 8 bytes, fewer than its 16-byte header" },
	{ "lowrank reserved", MODAL, m_lr_reserved, NULL, IRDM_EFORMAT, "STATIC_CORR_LOWRANK: reserved header words not 0" },
	{ "lowrank lambda NaN", MODAL, m_lr_lambda_nan, NULL, IRDM_EFORMAT, "STATIC_CORR_LOWRANK: lambda[1] is not finite" },
	{ "lowrank U inf", MODAL, m_lr_u_inf, NULL, IRDM_EFORMAT, "STATIC_CORR_LOWRANK: U element (column 1, axis 2, term 0) is not finite" },
	{ "lowrank elem", MODAL, m_lr_elem, w_lowrank_f64, IRDM_EFORMAT, "section STATIC_CORR_LOWRANK has element type F64, expected BYTES" },
	{ "lowrank without STATIC_CORR", MODAL, m_lr_no_corr, NULL, IRDM_EFORMAT, "STATIC_CORR_LOWRANK must not be present (its far field needs STATIC_CORR)" },
	{ "FIR + lowrank", FIR, NULL, w_add_lowrank, IRDM_EFORMAT, "STATIC_CORR_LOWRANK must not be present (FIR image)" },
#define CL "STATIC_CORR_CLUSTERS: "
	{ "clusters", MODAL, m_cl_ok, NULL, IRDM_OK, NULL },
	{ "clusters elem", MODAL, m_cl_ok, w_clusters_f64, IRDM_EFORMAT, "section STATIC_CORR_CLUSTERS has element type F64, expected BYTES" },
	{ "clusters short", MODAL, m_cl_short, NULL, IRDM_EFORMAT, "section STATIC_CORR_CLUSTERS has 24 bytes, fewer than its 32-byte header" },
	{ "clusters long", MODAL, m_cl_long, NULL, IRDM_EFORMAT, "section STATIC_CORR_CLUSTERS has 296 bytes, expected 304 for 2 clusters and 24 values" },
	{ "clusters 0", MODAL, m_cl_none, NULL, IRDM_EFORMAT, CL "0 clusters is not in 1..2 (n_cols, at most 4096)" },
	{ "clusters > n_cols", MODAL, m_cl_many, NULL, IRDM_EFORMAT, CL "3 clusters is not in 1..2" },
	{ "clusters max_rank", MODAL, m_cl_max_rank, NULL, IRDM_EFORMAT, CL "max_rank 1025 is above 1024" },
	{ "clusters reserved", MODAL, m_cl_reserved, NULL, IRDM_EFORMAT, CL "reserved header words not 0" },
	{ "clusters n_values vs size", MODAL, m_cl_n_values, NULL, IRDM_EFORMAT, "section STATIC_CORR_CLUSTERS has 304 bytes, expected 312 for 2 clusters and 25 values" },
	{ "clusters n_values wraps", MODAL, m_cl_n_values_wrap, NULL, IRDM_EFORMAT, "section STATIC_CORR_CLUSTERS has 304 bytes, expected" },
	{ "clusters start 0", MODAL, m_cl_start0, NULL, IRDM_EFORMAT, CL "cluster starts run 1..2, expected 0..2 (n_cols)" },
	{ "clusters start n_cols", MODAL, m_cl_start_end, NULL, IRDM_EFORMAT, CL "cluster starts run 0..1, expected 0..2 (n_cols)" },
	{ "clusters empty", MODAL, m_cl_empty, NULL, IRDM_EFORMAT, CL "cluster 0 is empty or reversed (start 0, next 0)" },
	{ "clusters reversed", MODAL, m_cl_reversed, NULL, IRDM_EFORMAT, CL "cluster 1 is empty or reversed (start 3, next 2)" },
	{ "clusters member range", MODAL, m_cl_member_range, NULL, IRDM_EFORMAT, CL "member 0 is column 2, not below n_cols 2" },
	{ "clusters col_pos", MODAL, m_cl_col_pos, NULL, IRDM_EFORMAT, CL "column 1 is member 0, but col_pos says 1" },
	{ "clusters member repeat", MODAL, m_cl_member_repeat, NULL, IRDM_EFORMAT, CL "column 1 is member 1, but col_pos says 0" },
	{ "clusters padding", MODAL, m_cl_padding, NULL, IRDM_EFORMAT, CL "padding not 0" },
	{ "clusters self pair rank", MODAL, m_cl_self_rank, NULL, IRDM_EFORMAT, CL "self pair 0 has rank 2, must be dense" },
	{ "clusters last self pair rank", MODAL, m_cl_self_rank_last, NULL, IRDM_EFORMAT, CL "self pair 1 has rank 0, must be dense" },
	{ "clusters rank > 3 |a|", MODAL, m_cl_rank_size, NULL, IRDM_EFORMAT, CL "pair (0, 1) has rank 4, above min(3, 3, max_rank 4)" },
	{ "clusters rank > max_rank", MODAL, m_cl_rank_max, NULL, IRDM_EFORMAT, CL "pair (0, 1) has rank 2, above min(3, 3, max_rank 1)" },
	{ "clusters pair reserved", MODAL, m_cl_pair_reserved, NULL, IRDM_EFORMAT, CL "pair (0, 1) reserved word not 0" },
	{ "clusters offset gap", MODAL, m_cl_offset_gap, NULL, IRDM_EFORMAT, CL "pair (0, 1) starts at value 10, expected 6" },
	{ "clusters pairs vs n_values", MODAL, m_cl_pairs_short, NULL, IRDM_EFORMAT, CL "the pairs hold 18 values, the header says 24" },
	{ "clusters pairs past n_values", MODAL, m_cl_pairs_long, NULL, IRDM_EFORMAT, CL "pair (1, 1) runs past the header's 24 values (from value 24)" },
	{ "clusters NaN", MODAL, m_cl_nan, NULL, IRDM_EFORMAT, CL "value 3 is not finite" },
	{ "clusters inf", MODAL, m_cl_inf, NULL, IRDM_EFORMAT, CL "value 23 is not finite" },
	{ "clusters without STATIC_CORR", MODAL, m_cl_no_corr, NULL, IRDM_EFORMAT, "STATIC_CORR_CLUSTERS must not be present (its clusters need STATIC_CORR)" },
	{ "FIR + clusters", FIR, NULL, w_add_clusters, IRDM_EFORMAT, "STATIC_CORR_CLUSTERS must not be present (FIR image)" },
#undef CL
};

/* irdm_image_value(): the stored value times its column's scale; an
 * image without COLUMN_SCALE (every image before 2.4) reads as written. */
static void test_column_scale_values(void **state)
{
	struct irdm_image_writer w;
	struct img_fixture fx;
	struct irdm_image img;
	char err[256];
	size_t size, per;
	void *buf;

	(void)state;
	for (int scaled = 0; scaled < 2; scaled++) {
		small_fir(&fx);
		if (scaled)
			m_scale(&fx);
		irdm_iw_init(&w);
		img_fixture_add(&fx, &w);
		if (scaled)
			w_add_scales(&w);
		assert_int_equal(irdm_iw_to_buffer(&w, &buf, &size), 0);
		assert_int_equal(irdm_image_parse(buf, size, &img, err, sizeof(err)), IRDM_OK);
		assert_true(!img.col_scale == !scaled);
		per = (size_t)img.meta->n_nodes * img.meta->fir_length * 9;
		for (uint32_t c = 0; c < img.meta->n_cols; c++) {
			double sc = scaled ? scales_ok[c] : 1.0;
			assert_true(irdm_image_col_scale(&img, c) == sc);
			for (size_t i = c * per; i < (c + 1) * per; i++)
				assert_true(irdm_image_value(&img, img.fir, c, i) ==
					    irdm_elem_get(img.fir, img.meta->precision, i) * sc);
		}
		assert_true(irdm_elem_get(img.fir, img.meta->precision, per + 1) != 0);
		free(buf);
		img_fixture_free(&fx);
	}
}

/* The two-contact figure of PROVENANCE, read as written; -1 without it. */
static void test_two_contacts_read(void **state)
{
	struct irdm_image_writer w;
	struct img_fixture fx;
	struct irdm_image img;
	char err[256];
	size_t size;
	void *buf;

	(void)state;
	for (int with = 0; with < 2; with++) {
		small_fir(&fx);
		if (with)
			prov_two_contacts(&fx, "0.000394");
		irdm_iw_init(&w);
		img_fixture_add(&fx, &w);
		assert_int_equal(irdm_iw_to_buffer(&w, &buf, &size), 0);
		assert_int_equal(irdm_image_parse(buf, size, &img, err, sizeof(err)), IRDM_OK);
		assert_true(img.two_contacts_error == (with ? 0.000394 : -1.0));
		free(buf);
		img_fixture_free(&fx);
	}
}

static void test_semantic_validation(void **state)
{
	(void)state;
	for (size_t i = 0; i < sizeof(sem_cases) / sizeof(sem_cases[0]); i++) {
		const struct sem_case *c = &sem_cases[i];
		struct irdm_image_writer w;
		struct img_fixture fx;
		size_t size;
		void *buf;

		current_case = c->name;
		if (c->base == FIR)
			small_fir(&fx);
		else
			small_modal(&fx);
		if (c->fx_edit)
			c->fx_edit(&fx);
		irdm_iw_init(&w);
		img_fixture_add(&fx, &w);
		if (c->w_edit)
			c->w_edit(&w);
		assert_int_equal(irdm_iw_to_buffer(&w, &buf, &size), 0);
		expect_parse(buf, size, c->code, c->needle);
		free(buf);
		img_fixture_free(&fx);
	}
	current_case = "";
}

/* A newer minor may give STATIC_CORR_CLUSTERS' reserved words (header and
 * pair) a meaning: they are ignored there, refused at our own minor. */
static void test_clusters_reserved_newer_minor(void **state)
{
	struct irdm_image_header h;
	struct img_fixture fx;
	size_t size;
	uint8_t *buf;

	(void)state;
	small_modal(&fx);
	cl_hdr(&fx)->reserved[0] = 1;
	cl_pairs(&fx)[1].reserved = 1;
	fixture_buffer(&fx, (void **)&buf, &size);
	expect_parse(buf, size, IRDM_EFORMAT, "STATIC_CORR_CLUSTERS: reserved header words not 0");
	h = get_header(buf);
	h.version_minor = IRDM_IMAGE_VERSION_MINOR + 1;
	put_header(buf, &h);
	img_fixture_reseal(buf, size);
	expect_parse(buf, size, IRDM_OK, NULL);
	free(buf);
	img_fixture_free(&fx);
}

/* Empty payloads (no surface) are valid, also as the last section, where
 * the file ends at the (aligned) offset of the empty payload. */
static void test_empty_section(void **state)
{
	struct irdm_image_writer w;
	struct img_fixture fx;
	struct irdm_image img;
	char err[256];
	size_t size;
	uint8_t *buf;

	(void)state;
	assert_int_equal(img_fixture_fir(&fx, IRDM_ELEM_F32, 2, 1, 1), 0);
	assert_int_equal(fx.meta.n_tris, 0);
	fixture_buffer(&fx, (void **)&buf, &size);
	expect_parse(buf, size, IRDM_OK, NULL);
	free(buf);

	irdm_iw_init(&w);
	img_fixture_add(&fx, &w);
	w_remove(&w, IRDM_SEC_SURFACE);
	assert_int_equal(irdm_iw_add(&w, IRDM_SEC_SURFACE, IRDM_ELEM_U32,
				     NULL, 0),
			 0);
	assert_int_equal(irdm_iw_to_buffer(&w, (void **)&buf, &size), 0);
	assert_int_equal(size % 64, 0);
	assert_int_equal(get_entry(buf, w.n - 1).offset, size);
	assert_int_equal(irdm_image_parse(buf, size, &img, err, sizeof(err)), 0);
	assert_non_null(img.tris);
	free(buf);
	img_fixture_free(&fx);
}

static void test_f16_nan_in_fir(void **state)
{
	struct img_fixture fx;
	size_t size;
	void *buf;

	(void)state;
	assert_int_equal(img_fixture_fir(&fx, IRDM_ELEM_F16, 4, 1, 2), 0);
	((uint16_t *)fx.fir)[5] = 0x7e00;
	fixture_buffer(&fx, &buf, &size);
	expect_parse(buf, size, IRDM_EFORMAT, "FIR element 5");
	free(buf);
	((uint16_t *)fx.fir)[5] = 0xfc00; /* -inf */
	fixture_buffer(&fx, &buf, &size);
	expect_parse(buf, size, IRDM_EFORMAT, "FIR element 5");
	free(buf);
	((uint16_t *)fx.fir)[5] = 0x7bff; /* 65504: finite */
	fixture_buffer(&fx, &buf, &size);
	expect_parse(buf, size, IRDM_OK, NULL);
	free(buf);
	img_fixture_free(&fx);
}

/* The loader's codes have distinct descriptions in the project's error space. */
static void test_strerror(void **state)
{
	static const int codes[] = {
		IRDM_OK,
		IRDM_EINVAL,
		IRDM_ENOMEM,
		IRDM_EIO,
		IRDM_ETRUNC,
		IRDM_EMAGIC,
		IRDM_EVERSION,
		IRDM_ECRC,
		IRDM_ERANGE,
		IRDM_EMISSING,
		IRDM_EFORMAT,
	};

	(void)state;
	for (size_t c = 0; c < sizeof(codes) / sizeof(codes[0]); c++) {
		assert_true(strlen(irdm_strerror(codes[c])) > 0);
		for (size_t d = 0; d < c; d++)
			assert_string_not_equal(irdm_strerror(codes[c]),
						irdm_strerror(codes[d]));
	}
	assert_string_equal(irdm_strerror(IRDM_ECRC), "bad checksum");
	assert_true(strlen(irdm_strerror(-99)) > 0);
}

/* ------------------------------------------------------ writer atomicity */

static void test_write_missing_dir(void **state)
{
	struct img_fixture fx;
	char path[2 * PATH_MAX], dir[PATH_MAX], err[512] = "";

	(void)state;
	small_fir(&fx);
	path_in(dir, sizeof(dir), "no-such-dir");
	snprintf(path, sizeof(path), "%s/x.img", dir);
	assert_int_equal(img_fixture_write(&fx, path, err, sizeof(err)), IRDM_EIO);
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, strerror(ENOENT)));
	assert_null(strchr(err, '\n'));
	assert_int_equal(access(dir, F_OK), -1);
	assert_int_equal(count_tmp_files(tmpdir), 0);
	img_fixture_free(&fx);
}

static void test_write_replaces_atomically(void **state)
{
	struct img_fixture a, b;
	struct irdm_image img;
	char path[PATH_MAX], err[512];
	struct stat st;

	(void)state;
	small_fir(&a);
	small_modal(&b);
	path_in(path, sizeof(path), "replace.img");
	assert_int_equal(img_fixture_write(&a, path, err, sizeof(err)), 0);
	assert_int_equal(count_tmp_files(tmpdir), 0);
	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(st.st_mode & 0777, 0644);
	/* A mapping of the old image survives its replacement. */
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
	assert_int_equal(img_fixture_write(&b, path, err, sizeof(err)), 0);
	assert_int_equal(count_tmp_files(tmpdir), 0);
	assert_int_equal(img.meta->representation, IRDM_REPR_FIR);
	check_fir_values(&img, IRDM_ELEM_F32);
	irdm_image_unmap(&img);
	assert_int_equal(irdm_image_map(path, 0, &img, err, sizeof(err)), 0);
	assert_int_equal(img.meta->representation, IRDM_REPR_MODAL);
	irdm_image_unmap(&img);
	img_fixture_free(&a);
	img_fixture_free(&b);
}

static void test_write_over_directory_fails(void **state)
{
	struct img_fixture fx;
	char path[PATH_MAX], inner[2 * PATH_MAX], err[512] = "";
	struct stat st;
	size_t len;
	void *back;

	(void)state;
	small_fir(&fx);
	path_in(path, sizeof(path), "is-a-dir");
	assert_int_equal(mkdir(path, 0755), 0);
	snprintf(inner, sizeof(inner), "%s/keep", path);
	write_file(inner, "old content", 11);
	assert_int_equal(img_fixture_write(&fx, path, err, sizeof(err)), IRDM_EIO);
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, strerror(EISDIR)));
	assert_int_equal(stat(path, &st), 0);
	assert_true(S_ISDIR(st.st_mode));
	back = read_file(inner, &len);
	assert_int_equal(len, 11);
	assert_memory_equal(back, "old content", 11);
	free(back);
	assert_int_equal(count_tmp_files(tmpdir), 0);
	img_fixture_free(&fx);
}

/* A write that fails half way (file size limit: EFBIG) leaves the old
 * image byte for byte and no temporary file. */
static void test_write_failure_keeps_old_image(void **state)
{
	struct img_fixture small, big;
	char path[PATH_MAX], err[512] = "";
	struct rlimit old, lim;
	void (*old_handler)(int);
	void *before, *after;
	size_t blen, alen;
	int ret;

	(void)state;
	small_fir(&small);
	assert_int_equal(img_fixture_fir(&big, IRDM_ELEM_F64, 40, 10, 50), 0);
	path_in(path, sizeof(path), "keep.img");
	assert_int_equal(img_fixture_write(&small, path, err, sizeof(err)), 0);
	before = read_file(path, &blen);

	assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
	old_handler = signal(SIGXFSZ, SIG_IGN);
	lim = old;
	lim.rlim_cur = 64 * 1024; /* big image is ~1.4 MB */
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
	ret = img_fixture_write(&big, path, err, sizeof(err));
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
	signal(SIGXFSZ, old_handler);

	assert_int_equal(ret, IRDM_EIO);
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, strerror(EFBIG)));
	after = read_file(path, &alen);
	assert_int_equal(alen, blen);
	assert_memory_equal(after, before, blen);
	assert_int_equal(count_tmp_files(tmpdir), 0);
	free(before);
	free(after);
	img_fixture_free(&small);
	img_fixture_free(&big);
}

/* ------------------------------------------------------------------ main */

static int setup(void **state)
{
	const char *base = getenv("TMPDIR");

	(void)state;
	snprintf(tmpdir, sizeof(tmpdir), "%s/irdm-test-image.XXXXXX",
		 base && *base ? base : "/tmp");
	return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown(void **state)
{
	(void)state;
	return rm_tree(tmpdir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_crc32c_check_value),
		cmocka_unit_test(test_crc32c_all_lengths_and_alignments),
		cmocka_unit_test(test_f16_known_patterns),
		cmocka_unit_test(test_column_scale_values),
		cmocka_unit_test(test_two_contacts_read),
		cmocka_unit_test(test_f16_roundtrip_all),
		cmocka_unit_test(test_f16_rounding_all_midpoints),
		cmocka_unit_test(test_elem_size_and_get),
		cmocka_unit_test(test_writer_layout),
		cmocka_unit_test(test_writer_add_rejects),
		cmocka_unit_test(test_fir_roundtrip),
		cmocka_unit_test(test_modal_floating_roundtrip),
		cmocka_unit_test(test_modal_lowrank_roundtrip),
		cmocka_unit_test(test_modal_clusters_roundtrip),
		cmocka_unit_test(test_clusters_transpose_inexact),
		cmocka_unit_test(test_modal_grounded_f16_roundtrip),
		cmocka_unit_test(test_map_lock),
		cmocka_unit_test(test_map_errors),
		cmocka_unit_test(test_truncated_every_length),
		cmocka_unit_test(test_every_byte_flip_detected),
		cmocka_unit_test(test_bad_magic_and_version),
		cmocka_unit_test(test_bad_checksums),
		cmocka_unit_test(test_file_size_mismatch),
		cmocka_unit_test(test_table_out_of_range),
		cmocka_unit_test(test_section_out_of_range),
		cmocka_unit_test(test_padding_must_be_zero),
		cmocka_unit_test(test_unaligned_buffer),
		cmocka_unit_test(test_unknown_kind),
		cmocka_unit_test(test_semantic_validation),
		cmocka_unit_test(test_clusters_reserved_newer_minor),
		cmocka_unit_test(test_empty_section),
		cmocka_unit_test(test_f16_nan_in_fir),
		cmocka_unit_test(test_strerror),
		cmocka_unit_test(test_write_missing_dir),
		cmocka_unit_test(test_write_replaces_atomically),
		cmocka_unit_test(test_write_over_directory_fails),
		cmocka_unit_test(test_write_failure_keeps_old_image),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
