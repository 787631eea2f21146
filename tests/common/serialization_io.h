#pragma once
// Test helpers shared by the suites that write or read MRPT objects.
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/serialization/CSerializable.h>

#include <cstdint>
#include <string>
#include <vector>

namespace codemark::test
{
/** \a obj serialized as MRPT writes it into a rawlog (class name, version, data). */
inline std::vector<uint8_t> toBytes(const mrpt::serialization::CSerializable& obj)
{
	mrpt::io::CMemoryStream mem;
	auto ar = mrpt::serialization::archiveFrom(mem);
	ar << obj;
	const auto* p = static_cast<const uint8_t*>(mem.getRawBufferData());
	return {p, p + mem.getTotalBytesCount()};
}

/** The object stored in \a bytes; throws on anything unreadable. */
inline mrpt::serialization::CSerializable::Ptr fromBytes(const std::vector<uint8_t>& bytes)
{
	mrpt::io::CMemoryStream mem;
	mem.assignMemoryNotOwn(bytes.data(), bytes.size());
	auto ar = mrpt::serialization::archiveFrom(mem);
	return ar.ReadObject();
}

/** Every object of a rawlog (either format, gzipped or not), in order. */
inline std::vector<mrpt::serialization::CSerializable::Ptr> readRawlog(const std::string& path)
{
	mrpt::io::CFileGZInputStream in(path);
	auto ar = mrpt::serialization::archiveFrom(in);
	std::vector<mrpt::serialization::CSerializable::Ptr> out;
	for (;;)
	{
		try
		{
			out.push_back(ar.ReadObject());
		}
		catch (const mrpt::serialization::CExceptionEOF&)
		{
			break;
		}
	}
	return out;
}
}  // namespace codemark::test
