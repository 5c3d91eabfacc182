/* bind_field.c — language binding (being written). */
#include "builtin.h"

int bind_field_init(interp *I)
{
    (void)I;
    return 0;
}
