/* robot.c: the arm behind robot.h, from its generated <robot>_kinds.h, which names the
 * generated functions (DYNGEN_KINDS and the like). Compiled per arm with
 * -DDYNGEN_KINDS_H='"<robot>_kinds.h"' and the arm's generated folder on the include path. */
#include "robot.h"
#include DYNGEN_KINDS_H

#ifdef DYNGEN_ROBOT_USE_FLOAT
#error "the extractor needs the double build of the generated C"
#endif

const int dyngen_links = DYNGEN_LINKS;
const dyngen_kind dyngen_kinds[] = {DYNGEN_KINDS};
const int dyngen_kind_count = (int)(sizeof dyngen_kinds / sizeof dyngen_kinds[0]);

void dyngen_standard_from_dynamic(const double *p, double *s)
{
    DYNGEN_STANDARD_FROM_DYNAMIC(p, s);
}
