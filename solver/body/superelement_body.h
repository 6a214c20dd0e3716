// A superelement in absolute interface coordinates (thesis ch. 3-4, 8.1; tangent stiffness paper).
//
// System coordinates of one body: for each interface node k its position x_k and rotation R_k
// (variations dx_k, spatial dpi_k), then the internal modal coordinates eta. The floating frame
// (x_j, R_j) is not a coordinate: it solves Phi_CB q_loc = 0 (thesis 3.7, 4.2) by Newton.
//
// Local coordinates (thesis 3.1): u_k = R_j^T (x_k - x_j) - X_k,
//   theta_k = log(R_j^T R_k R0_k^T), eta.
// Their variation, exact to first order:  d q_loc = B Rbar^T d q,  B = D T  with
//   D = blockdiag(1, J_l^-1(theta_k), 1)         (exact rotation kinematics; the thesis uses D = 1)
//   Phi_rig rows [1, -r~_k; 0, 1], r_k = X_k + u_k (thesis 3.14)
//   S = Phi_CB D Phi_rig, Z = S^-1 Phi_CB D       (thesis 3.17 with D)
//   T = 1 - Phi_rig Z                              (thesis 3.18)
// Elastic force, the gradient of V = q_loc^T K q_loc / 2:  f = Rbar B^T K q_loc  (thesis 4.12).
// With modal derivatives (thesis 8.3) V is the file's quartic polynomial (Green-Lagrange inside
// the body) and K q_loc becomes its gradient Q(q_loc), K its Hessian in K1; K2-K4 use Q as they
// are written.
// Tangent (exact derivative, checked against finite differences), local part of
// K_t = Rbar (K1 + K2 + K3 + K4) Rbar^T:
//   K1 = B^T K B                                   (thesis 4.25)
//   K2 = -Z^T Fhat^T B,  Fhat from Qhat = B^T K q   (thesis 4.32)
//   K3 = -(Fhat + Mhat) Z                           (thesis 4.37)
//   K4 = T^T G B, G = blockdiag(d/dtheta [J_l^-T(theta_k) v_k]), v = P^T K q,
//        P = 1 - D Phi_rig S^-1 Phi_CB              (from D; zero when D = 1)
// Option `approximated` (thesis 3.23, 5.3): the force uses the constant T0 = 1 - Phi_rig0 Phi_CB,
// f = Rbar T0^T K q_loc; its tangent is the exact derivative of that force.
//
// The model and one evaluation's data are in body_model.h; the kernels, free functions
// f(const SuperelementBody&, BodyData&, ...), one concept per header below.
#pragma once

#include "solver/body/body_model.h"
#include "solver/body/corotational_inertia.h"
#include "solver/body/elastic_force.h"
#include "solver/body/exact_inertia.h"
#include "solver/body/floating_frame.h"
#include "solver/body/inertia_force.h"
#include "solver/body/inertia_stiffening.h"
#include "solver/body/momentum_source.h"
