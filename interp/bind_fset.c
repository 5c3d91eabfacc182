/* bind_fset.c — language binding (being written). */
#include "builtin.h"

int bind_fset_init(interp *I)
{
    (void)I;
    return 0;
}
