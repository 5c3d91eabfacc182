/* bind_solid.c — language binding (being written). */
#include "builtin.h"

int bind_solid_init(interp *I)
{
    (void)I;
    return 0;
}
