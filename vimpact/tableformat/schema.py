"""The schema of a vimpact table.

Its columns with their units and meaning, the row statuses and the schema version.

The sweep writes these columns (:meth:`vimpact.sweep.spec.SweepSpec.columns` picks
those of a spec) and stores :data:`COLUMNS`' units and meanings in the table's
metadata (``units``, ``columns``); the reader (:mod:`vimpact.lookup.table`) reads
them. Statuses come from the one status table, :mod:`vimpact.kernels.status`.
"""

from __future__ import annotations

from vimpact.kernels.status import TABLE as STATUS_TABLE

#: Version of the table layout (columns, metadata keys and random draws): 3 since
#: the draws are made per chunk from ``SeedSequence(seed, spawn_key=(chunk,))``; 4 since
#: every table has the friction outputs (``mu_eff``, ``rebound_angle_deg``,
#: ``gross_slip_fraction``, ``friction_energy_J``), a spec with friction the inputs
#: ``mu`` and ``psi``, and Kelvin-Voigt and elastic grid rows ``Q2 = NaN`` (not 0).
#: The random draws of version 3 are unchanged.
SCHEMA_VERSION = 4

#: Row statuses of a sweep table: those of :data:`vimpact.STATUSES` and ``failed``
#: (the status table, :mod:`vimpact.kernels.status`).
SWEEP_STATUSES = {s.name: s.message for s in STATUS_TABLE}

# ---- columns ----------------------------------------------------------------

#: Unit and meaning of every column a sweep table can have.
COLUMNS = {
    "row": ("", "row index, 0-based: chunk c holds rows c * chunk_size ..."),
    "E_Pa": ("Pa", "Young's modulus (relaxed) as drawn"),
    "G_Pa": ("Pa", "shear modulus (Kelvin-Voigt, elastic) or relaxed modulus G_inf (Prony)"),
    "G1_Pa": ("Pa", "standard solid: parallel spring G1 (relaxed modulus)"),
    "G2_Pa": ("Pa", "standard solid: spring G2 of the Maxwell arm"),
    "eta_Pa_s": ("Pa s", "viscosity: Kelvin-Voigt dashpot, standard-solid arm dashpot, "
                         "Prony parallel dashpot"),
    "R_m": ("m", "sphere radius"),
    "m_kg": ("kg", "sphere mass"),
    "v_z0_m_s": ("m/s", "normal impact speed (into the half-space)"),
    "v_x0_m_s": ("m/s", "tangential speed of the centre"),
    "omega0_rad_s": ("rad/s", "spin about the y axis"),
    "angle_deg": ("deg", "impact angle from the normal as drawn: v_x0 = v_z0 tan(angle)"),
    "mu": ("1", "Coulomb friction coefficient, static = kinetic (inf: full stick)"),
    "Q1": ("1", "damping parameter sqrt(15/32) (eta/G_inf) / T"),
    "Q2": ("1", "stiffness ratio G1/G2 (standard solid; inf without an arm, eta = 0). "
                "Kelvin-Voigt and elastic rows have no G2: NaN, meaning G2 -> inf (the "
                "Kelvin-Voigt limit of the standard solid), never 0 (which would read as "
                "G1 = 0, a Maxwell fluid, and as log 0 on a log Q2 axis)"),
    "nu": ("1", "Poisson ratio"),
    "theta_ratio": ("1", "moment of inertia Theta / (m R^2)"),
    "psi": ("1", "incidence of Maw, Barber and Fawcett 2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0 "
                 "(0: full stick, mu = inf, or v_c0 = 0; inf: mu = 0 with v_c0 != 0)"),
    "e_z": ("1", "normal restitution |v_z,end| / v_z0"),
    "e_x": ("1", "tangential restitution |v_c,end| / |v_c0|"),
    "beta_x": ("1", "signed tangential restitution -v_c,end / v_c0"),
    "energy_ratio": ("1", "kinetic energy after / before"),
    "t_contact_s": ("s", "contact time"),
    "u_max_m": ("m", "maximum indentation"),
    "a_max_m": ("m", "maximum contact half-width"),
    "t_hertz_s": ("s", "Hertz contact time of the relaxed modulus"),
    "d_hertz_m": ("m", "Hertz maximum indentation of the relaxed modulus"),
    "a_hertz_m": ("m", "Hertz contact radius of the relaxed modulus"),
    "t_contact_rel": ("1", "t_contact / t_hertz"),
    "u_max_rel": ("1", "u_max / d_hertz"),
    "a_max_rel": ("1", "a_max / a_hertz"),
    "v_z_end_m_s": ("m/s", "normal velocity at the end (negative: rebound)"),
    "v_x_end_m_s": ("m/s", "tangential velocity of the centre at the end"),
    "omega_end_rad_s": ("rad/s", "spin at the end"),
    "mu_eff": ("1", "impulse ratio |int F_x dt| / int F_z dt (mu in gross slip; NaN when "
                    "v_c0 = 0)"),
    "rebound_angle_deg": ("deg", "angle of the centre's rebound velocity to the normal"),
    "gross_slip_fraction": ("1", "fraction of the contact time in gross slip (every element "
                                 "in contact slipping; 0 in full stick; NaN when v_c0 = 0)"),
    "friction_energy_J": ("J", "energy dissipated by slip (0 in full stick)"),
    "adhesion_J_m2": ("J/m^2", "work of adhesion dgamma (docs/physics.md#adhesion)"),
    "lam": ("1", "adhesion number sqrt(2 pi a_H dgamma / E*) / d (Hertz scales of the "
                 "relaxed modulus)"),
    "F_tensile_max_N": ("N", "largest pulling force on the sphere (0 without adhesion)"),
    "model": ("", "rheology of the row: elastic, kelvin_voigt, standard_solid or prony "
                  "(a Kelvin-Voigt row has Q2 = NaN)"),
    "path": ("", "the kernel that ran the row (vimpact.engine.routing; why: the paths metadata)"),
    "status": ("", "outcome of the row, see the statuses metadata"),
    "error": ("", "why the row failed before or in the simulation (null otherwise)"),
}

#: Result columns: sweep name -> column of :func:`vimpact.simulate_batch`.
RESULTS = {
    "e_z": "e_z", "e_x": "e_x", "beta_x": "beta_x", "energy_ratio": "energy_ratio",
    "t_contact_s": "t_contact", "u_max_m": "u_max", "a_max_m": "a_max",
    "t_hertz_s": "t_hertz", "d_hertz_m": "d_hertz", "a_hertz_m": "a_hertz",
    "v_z_end_m_s": "v_z_end", "v_x_end_m_s": "v_x_end", "omega_end_rad_s": "omega_end",
    "mu_eff": "mu_eff", "rebound_angle_deg": "rebound_angle",
    "gross_slip_fraction": "gross_slip_fraction", "friction_energy_J": "friction_energy",
}
RELATIVE = {"t_contact_rel": ("t_contact_s", "t_hertz_s"), "u_max_rel": ("u_max_m", "d_hertz_m"),
             "a_max_rel": ("a_max_m", "a_hertz_m")}
OUTPUTS = ("e_z", "e_x", "beta_x", "energy_ratio", "t_contact_s", "u_max_m", "a_max_m",
            "t_hertz_s", "d_hertz_m", "a_hertz_m", "t_contact_rel", "u_max_rel", "a_max_rel",
            "v_z_end_m_s", "v_x_end_m_s", "omega_end_rad_s", "mu_eff", "rebound_angle_deg",
            "gross_slip_fraction", "friction_energy_J")
#: Outputs of a table with adhesion (a ``lam`` axis or ``adhesion_J_m2`` drawn), after
#: :data:`OUTPUTS`.
ADHESION_OUTPUTS = ("F_tensile_max_N",)
#: Their columns of :func:`vimpact.simulate_batch`.
ADHESION_RESULTS = {"F_tensile_max_N": "F_tensile_max"}
#: Outputs that are NaN when v_c0 = 0 (no tangential force).
TANGENTIAL_OUTPUTS = ("e_x", "beta_x", "mu_eff", "gross_slip_fraction")
#: String columns: the row's rheology (``model``: elastic, kelvin_voigt, standard_solid or
#: prony; tells a Kelvin-Voigt row's ``Q2 = NaN`` apart), and path, status, error (null where
#: not applicable: path of a row that never ran, error of a good row).
LABELS = ("model", "path", "status", "error")


__all__ = ["ADHESION_OUTPUTS", "ADHESION_RESULTS", "COLUMNS", "LABELS", "OUTPUTS", "RELATIVE",
           "RESULTS", "SCHEMA_VERSION", "SWEEP_STATUSES", "TANGENTIAL_OUTPUTS"]
