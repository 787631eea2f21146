#pragma once
/** \file rawlog_check.h
 * Integrity check of a gzip-compressed rawlog before it is read. MRPT's
 * CFileGZInputStream reports a corrupt or cut deflate stream as a plain end
 * of file, so a rawlog with flipped bits reads as a shorter, valid one: a
 * silent wrong answer. zlib's own CRC and length check catches it.
 * Needs zlib (ZLIB::ZLIB).
 */
#include <zlib.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace codemark::app
{
/** Throws std::runtime_error "PATH: corrupt gzip data ... " when \a path is
 * gzip-compressed and its data does not decompress to the end with a good
 * CRC; does nothing for an uncompressed file. Costs one decompression pass. */
inline void checkRawlogGzip(const std::string& path)
{
	unsigned char magic[2] = {0, 0};
	if (std::FILE* f = std::fopen(path.c_str(), "rb"))
	{
		const size_t n = std::fread(magic, 1, 2, f);
		std::fclose(f);
		if (n < 2 || magic[0] != 0x1f || magic[1] != 0x8b) return;
	}
	else
		return;	 // the reader reports missing files itself
	gzFile gz = gzopen(path.c_str(), "rb");
	if (!gz) return;
	static char buf[1 << 16];
	long long total = 0;
	int n = 0;
	while ((n = gzread(gz, buf, sizeof(buf))) > 0) total += n;
	int err = Z_OK;
	const char* msg = gzerror(gz, &err);
	const std::string what = msg ? msg : "";
	gzclose(gz);
	if (n < 0 || (err != Z_OK && err != Z_STREAM_END))
		throw std::runtime_error(
			path + ": corrupt gzip data after " + std::to_string(total) + " decompressed bytes (" +
			what + "); the rawlog is damaged");
}
}  // namespace codemark::app
