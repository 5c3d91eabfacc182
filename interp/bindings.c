/* bindings.c — registers the language bindings of the runtime engines.
 * Each engine's binding lives in its own interp/bind_NAME.c. */
#include "builtin.h"

int bind_volume_init(interp *I);
int bind_all_init(interp *I)
{
    return bind_volume_init(I) || bind_field_init(I) || bind_ifs_init(I) || bind_solid_init(I) ||
           bind_ist_init(I) || bind_wrinkly_init(I) || bind_raster_init(I) || bind_show_init(I) ||
           bind_fset_init(I) || bind_shape_init(I) || bind_tops_init(I) || bind_superifs_init(I) ||
           bind_tiles_init(I) || bind_fit_init(I);
}
