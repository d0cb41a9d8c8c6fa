component thermal_comp "Thermal compensation of machine vmc3_thermal through external axis offsets";
// written by chain export --controller linuxcnc-thermal (docs/export-controllers.md, "Thermal compensation")
pin in float temp_t_x = 20 "T_x (degC; unconnected: its reference, no offset)";
pin in float temp_t_front = 20 "T_front (degC; unconnected: its reference, no offset)";
pin in float temp_t_rear = 20 "T_rear (degC; unconnected: its reference, no offset)";
pin in float temp_t_head = 20 "T_head (degC; unconnected: its reference, no offset)";
pin in float temp_t_coltop = 20 "T_coltop (degC; unconnected: its reference, no offset)";
pin in float pos_y "axis Y position (axis.y.pos-cmd)";
pin out s32 counts_y "to axis.y.eoffset-counts";
pin out float offset_y "the offset (mm)";
pin in float pos_x "axis X position (axis.x.pos-cmd)";
pin out s32 counts_x "to axis.x.eoffset-counts";
pin out float offset_x "the offset (mm)";
pin in float pos_z "axis Z position (axis.z.pos-cmd)";
pin out s32 counts_z "to axis.z.eoffset-counts";
pin out float offset_z "the offset (mm)";
pin in bit is_on "halui.machine.is-on";
pin in bit homed "motion.is-all-homed";
param rw float k = 100000 "counts per mm; axis.L.eoffset-scale = 1/k";
option period no;
function _;
license "GPL";
;;
static int counts(double mm, double k) { return mm >= 0 ? (int)(mm * k + 0.5) : (int)(mm * k - 0.5); }
FUNCTION(_) {
    double d;
    d = (0) + (0)*(pos_y - 0);
    if (!is_on || !homed) d = 0;
    offset_y = d;
    counts_y = counts(d, k);
    d = (0) + (0)*(pos_x - 0);
    if (!is_on || !homed) d = 0;
    offset_x = d;
    counts_x = counts(d, k);
    d = (3.92888161392e-3*(temp_t_front-20)-2.25673944657e-3*(temp_t_rear-20)+3.06111767847e-3*(temp_t_head-20)-1.73926199749e-3*(temp_t_coltop-20)) + (0)*(pos_z - 0);
    if (!is_on || !homed) d = 0;
    offset_z = d;
    counts_z = counts(d, k);
}
