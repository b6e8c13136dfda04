//! Closed-form and quadrature references for flatland irradiance.
