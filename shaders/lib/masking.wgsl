#define_import_path lobes::masking

// Smith masking-shadowing from the two directions' masking terms G1(wi), G1(wr) (each in [0, 1]);
// CPU twin: src/reference/masking.rs. Written with G1 = 1 / (1 + Lambda) rather than Lambda,
// so that grazing directions (Lambda -> inf, G1 -> 0) stay finite.

// Separable G2 = G1(wi) G1(wr) (Heitz 2014, eq. 98).
fn masking_separable(gi: f32, gr: f32) -> f32 {
    return gi * gr;
}

// Height-correlated G2 = 1 / (1 + Lambda(wi) + Lambda(wr)) (Heitz 2014, eq. 99)
// = G1i G1r / (G1i + G1r - G1i G1r).
fn masking_height_correlated(gi: f32, gr: f32) -> f32 {
    if (gi <= 0.0 || gr <= 0.0) {
        return 0.0;
    }
    return gi * gr / (gi + gr - gi * gr);
}
