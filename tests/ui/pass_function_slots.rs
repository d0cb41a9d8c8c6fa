// Function slots and `errors: iso` in both forms of `machine!`: the
// coefficients are error parameters like any other.
use chain::core::ErrorModel;

chain::machine! {
    pub Slide {
        bodies {
            bed {},
            x_slide {
                parent: bed,
                joint: { type: prismatic, axis: +x, variable: x },
                errors: {
                    dx: EXX,
                    dy: [dyc, { name: EYX, powers: [1, 2] }],
                    dz: { name: EZX, basis: legendre, degree: 2, range: [0, 1000] },
                },
            },
            z_slide { parent: bed, joint: { type: prismatic, axis: +z, variable: z }, errors: iso },
        },
        workpiece: x_slide,
        tool: z_slide,
    }
}

chain::machine!(pub FromFile = "tests/ui/pass_function_slots.yaml");

pub fn main() {
    assert_eq!(
        Slide::ERRORS,
        [
            "EXX", "dyc", "EYX_1", "EYX_2", "EZX_0", "EZX_1", "EZX_2", "EXZ", "EYZ", "EZZ", "EAZ",
            "EBZ", "ECZ"
        ]
    );
    // The tool rides on z, the workpiece on x: the x slide's linear errors
    // enter with a minus sign, py = EYZ − (dyc + EYX_1·x + EYX_2·x²) and
    // pz = EZZ − (EZX_0 + EZX_1·t + EZX_2·P_2(t)), t = (2x − 1000)/1000.
    let x = 750.0;
    let s = Slide::sensitivity(&[x, 0.0], &[]);
    assert_eq!(s[1][Slide::ERR_DYC], -1.0);
    assert_eq!(s[1][Slide::ERR_EYX_1], -x);
    assert_eq!(s[1][Slide::ERR_EYX_2], -x * x);
    let t: f64 = (2.0 * x - 1000.0) / 1000.0;
    assert!((s[2][Slide::ERR_EZX_1] + t).abs() < 1e-15);
    assert!((s[2][Slide::ERR_EZX_2] + (3.0 * t * t - 1.0) / 2.0).abs() < 1e-15);
    assert_eq!(s[1][Slide::ERR_EYZ], 1.0);
    let model: &dyn ErrorModel = &FromFile;
    assert_eq!(model.errors(), ["EXX", "EAC_0", "EAC_c1", "EAC_s1"]);
}
