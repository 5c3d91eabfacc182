/* bind_wrinkly.c — language binding (being written). */
#include "builtin.h"

int bind_wrinkly_init(interp *I)
{
    (void)I;
    return 0;
}
