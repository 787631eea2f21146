// Registers every serializable class of the plugin once, when the library is
// loaded (IMPLEMENTS_SERIALIZABLE does not register in MRPT 2.5.8).
#include <codemark/mrpt/CCodedLandmarksMap.h>
#include <codemark/mrpt/CObservationCodedLandmarks.h>
#include <mrpt/core/initializer.h>
#include <mrpt/rtti/CObject.h>

MRPT_INITIALIZER(codemark_mrpt_register_classes)
{
	mrpt::rtti::registerClass(CLASS_ID(codemark::CObservationCodedLandmarks));
	mrpt::rtti::registerClass(CLASS_ID(codemark::CCodedLandmarksMap));
}
