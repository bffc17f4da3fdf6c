"""How the process serves requests: the control, motion and goal planes (`spinning`), the
table-driven services (`adapter`) and their conversions, responses sent again (`responses`),
goals that wait without a thread (`waiting`) and parameters that take effect (`parameters`)."""
