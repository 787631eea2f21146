// A downstream program built against an installed codemark.
#include <codemark/landmark/codebook.h>
#include <codemark/landmark/geometry.h>

#include <iostream>

int main()
{
	const auto id = codemark::decodeCells(codemark::encodeId(37));
	const codemark::LandmarkGeometry g;
	if (!id || g.innerHalf() != 0.08) return 1;
	std::cout << "consumer: id 37 decodes to " << *id << "\n";
	return 0;
}
