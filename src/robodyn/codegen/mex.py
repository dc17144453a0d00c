"""MATLAB/Octave MEX gateway over the generated C, and a Level-2 MATLAB S-function for Simulink.

``<robot>_mex.c`` includes ``<robot>.c`` (written beside it by :func:`robodyn.codegen.c.c_files`
with prefix ``<robot>_``) and exposes every kernel through one entry point::

    out = <robot>_mex('inverse_dynamics', q, qd, qdd)    % q, qd, qdd: n x N, one state per column
    M   = <robot>_mex('mass_matrix', q)                  % n x n x N
    T   = <robot>_mex('forward_kinematics', q)           % 4 x 4 x N
    n   = <robot>_mex('dof')

Vector results are ``r x N``, matrix results ``r x c x N`` (``r x c`` for one state), indexed
naturally: the gateway copies the C row-major results into MATLAB's column-major arrays. Inputs
must be real full double matrices with the kernel's number of rows and a common number of
columns; anything else raises ``robodyn:mex:*`` errors (mexErrMsgIdAndTxt). Build with
``mex <robot>_mex.c`` (MATLAB) or ``mkoctfile --mex <robot>_mex.c`` (Octave).

``<robot>_sfun.m`` is a Level-2 MATLAB S-function block: input port tau (n), output ports q and
qd (n each), 2 n continuous states ``x = [q; qd]`` with derivatives from the MEX's
``state_derivative``, dialog parameter ``x0`` (2 n initial state). Octave has no Simulink, so
robodyn's tests exercise it only through a stand-in for the Simulink block object.
"""

from __future__ import annotations

from robodyn.codegen.base import NATURAL, GeneratedFile, identifier, provenance
from robodyn.codegen.kernels import Kernel, KernelSet


def _comment_block(lines: list[str], lead: str) -> str:
    return "\n".join(f"{lead} {line}".rstrip() for line in lines) + "\n"


_HELPERS = r"""
/* The inputs after the kernel name: real full double matrices with rows[k] rows and a common
 * number of columns (the number of states), which is returned. */
static mwSize rd_columns(const char *kernel, int nrhs, const mxArray *prhs[], int nin,
                         const char *const *names, const mwSize *rows) {
    mwSize count = 0;
    if (nrhs != nin + 1)
        mexErrMsgIdAndTxt("robodyn:mex:nargin", "%s takes %d input(s) after the kernel name, got %d",
                          kernel, nin, nrhs - 1);
    for (int k = 0; k < nin; ++k) {
        const mxArray *a = prhs[k + 1];
        if (!mxIsDouble(a) || mxIsComplex(a) || mxIsSparse(a) || mxGetNumberOfDimensions(a) != 2)
            mexErrMsgIdAndTxt("robodyn:mex:type", "%s: %s must be a real full double matrix",
                              kernel, names[k]);
        if (mxGetM(a) != rows[k])
            mexErrMsgIdAndTxt("robodyn:mex:size", "%s: %s must have %d rows (one state per column), "
                              "got %d", kernel, names[k], (int)rows[k], (int)mxGetM(a));
        if (k == 0)
            count = mxGetN(a);
        else if (mxGetN(a) != count)
            mexErrMsgIdAndTxt("robodyn:mex:size", "%s: %s has %d columns but %s has %d", kernel,
                              names[k], (int)mxGetN(a), names[0], (int)count);
    }
    return count;
}

/* The result array: rows x count for a vector kernel, rows x cols x count for a matrix kernel. */
static mxArray *rd_result(mwSize rows, mwSize cols, int matrix, mwSize count) {
    mwSize dims[3];
    dims[0] = rows;
    if (!matrix) {
        dims[1] = count;
        return mxCreateNumericArray(2, dims, mxDOUBLE_CLASS, mxREAL);
    }
    dims[1] = cols;
    dims[2] = count;
    return mxCreateNumericArray(3, dims, mxDOUBLE_CLASS, mxREAL);
}

/* MATLAB is column-major: entry (i, j) of the C row-major result goes to i + j rows. */
static void rd_transpose(double *dst, const double *src, mwSize rows, mwSize cols) {
    for (mwSize i = 0; i < rows; ++i)
        for (mwSize j = 0; j < cols; ++j)
            dst[i + j * rows] = src[i * cols + j];
}
"""


def _kernel_gateway(kernel: Kernel, prefix: str) -> str:
    """The static function serving one kernel: check, allocate, loop over states, transpose."""
    out = kernel.outputs[0]
    rows, cols = (out.shape[0], 1) if len(out.shape) == 1 else out.shape
    nin = len(kernel.inputs)
    names = ", ".join(f'"{a.name}"' for a in kernel.inputs)
    widths = ", ".join(str(a.size) for a in kernel.inputs)
    lines = [
        f"/* {kernel.name}: {kernel.summary}. */",
        f"static void rd_gateway_{kernel.name}(mxArray *plhs[], int nrhs, const mxArray *prhs[]) {{",
        f"    static const char *const names[] = {{{names}}};",
        f"    static const mwSize rows[] = {{{widths}}};",
        f"    const mwSize count = rd_columns(\"{kernel.name}\", nrhs, prhs, {nin}, names, rows);",
        f"    mxArray *result = rd_result({rows}, {cols}, {int(len(out.shape) == 2)}, count);",
        "    double *dst = mxGetPr(result);",
    ]
    lines += [f"    const double *{a.name} = mxGetPr(prhs[{k + 1}]);" for k, a in enumerate(kernel.inputs)]
    call = ", ".join(f"{a.name} + k * {a.size}" for a in kernel.inputs)
    lines += [
        f"    double buffer[{out.size}];",
        "    for (mwSize k = 0; k < count; ++k) {",
        f"        {prefix}{kernel.name}({call}, buffer);",
        f"        rd_transpose(dst + k * {out.size}, buffer, {rows}, {cols});",
        "    }",
        "    plhs[0] = result;",
        "}",
    ]
    return "\n".join(lines) + "\n"


def mex_source(kset: KernelSet, c_name: str, prefix: str) -> str:
    """Text of ``<robot>_mex.c``, including the C source file ``c_name`` (functions ``prefix*``)."""
    gateway = f"{identifier(kset.robot_name)}_mex"
    kernels = ", ".join(kset.names)
    parts = [
        _comment_block(provenance(kset, "MATLAB/Octave MEX gateway (C)"), "//").rstrip(),
        f"// Usage: out = {gateway}(KERNEL, inputs...) with KERNEL one of {kernels}, or 'dof'.",
        "// Inputs: n x N (one state per column). Outputs: r x N or r x c x N, indexed naturally.",
        f"// Build: mex {gateway}.c   or   mkoctfile --mex {gateway}.c   (with {c_name} beside it)",
        "#include <string.h>",
        '#include "mex.h"',
        f'#include "{c_name}"',
        _HELPERS,
    ]
    parts += [_kernel_gateway(k, prefix) for k in kset.kernels]
    body = [
        "void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[]) {",
        "    char kernel[64];",
        "    if (nrhs < 1 || !mxIsChar(prhs[0]) || mxGetString(prhs[0], kernel, sizeof kernel) != 0)",
        f"        mexErrMsgIdAndTxt(\"robodyn:mex:usage\", \"usage: {gateway}(KERNEL, inputs...) with KERNEL "
        f"one of {kernels}, or 'dof'\");",
        "    if (nlhs > 1)",
        f"        mexErrMsgIdAndTxt(\"robodyn:mex:nargout\", \"{gateway} returns one array, %d requested\",",
        "                          nlhs);",
        "    if (strcmp(kernel, \"dof\") == 0) {",
        f"        plhs[0] = mxCreateDoubleScalar({kset.dof});",
        "        return;",
        "    }",
    ]
    for k in kset.kernels:
        body += [f"    if (strcmp(kernel, \"{k.name}\") == 0) {{",
                 f"        rd_gateway_{k.name}(plhs, nrhs, prhs);",
                 "        return;",
                 "    }"]
    body += [f"    mexErrMsgIdAndTxt(\"robodyn:mex:kernel\", \"unknown kernel '%s'; choose one of {kernels}, "
             "or 'dof'\", kernel);",
             "}"]
    parts.append("\n".join(body) + "\n")
    return "\n".join(parts)


def sfunction_source(kset: KernelSet) -> str:
    """Text of ``<robot>_sfun.m``, a Level-2 MATLAB S-function calling ``<robot>_mex``."""
    stem = identifier(kset.robot_name)
    n = kset.dof
    help_lines = [
        f"{stem.upper()}_SFUN Level-2 MATLAB S-function: forward dynamics of {kset.robot_name}.",
        f"  Input port 1: joint torques tau ({n}). Output ports: q ({n}) and qd ({n}).",
        f"  Continuous states x = [q; qd] ({2 * n}), xd = {stem}_mex('state_derivative', x, tau).",
        f"  Dialog parameter: x0, the initial state ({2 * n} values, q then qd).",
        f"  Needs the MEX gateway on the path: mex {stem}_mex.c (with {kset.robot_name}.c beside it).",
        "",
        *provenance(kset, "Simulink Level-2 MATLAB S-function", NATURAL),
    ]
    return "\n".join([
        f"function {stem}_sfun(block)",
        _comment_block(help_lines, "%").rstrip(),
        "  setup(block);",
        "end",
        "",
        "function setup(block)",
        "  block.NumDialogPrms = 1;",
        "  block.DialogPrmsTunable = {'Nontunable'};",
        "  block.NumInputPorts = 1;",
        "  block.NumOutputPorts = 2;",
        "  block.SetPreCompInpPortInfoToDynamic;",
        "  block.SetPreCompOutPortInfoToDynamic;",
        f"  block.InputPort(1).Dimensions = {n};",
        "  block.InputPort(1).DatatypeID = 0;",
        "  block.InputPort(1).Complexity = 'Real';",
        "  block.InputPort(1).SamplingMode = 'Sample';",
        "  % tau enters only the derivatives: no direct feedthrough to q, qd",
        "  block.InputPort(1).DirectFeedthrough = false;",
        "  for k = 1:2",
        f"    block.OutputPort(k).Dimensions = {n};",
        "    block.OutputPort(k).DatatypeID = 0;",
        "    block.OutputPort(k).Complexity = 'Real';",
        "    block.OutputPort(k).SamplingMode = 'Sample';",
        "  end",
        f"  block.NumContStates = {2 * n};",
        "  block.SampleTimes = [0 0];",
        "  block.SimStateCompliance = 'DefaultSimState';",
        "  block.RegBlockMethod('CheckParameters', @check_parameters);",
        "  block.RegBlockMethod('InitializeConditions', @initialize_conditions);",
        "  block.RegBlockMethod('Outputs', @outputs);",
        "  block.RegBlockMethod('Derivatives', @derivatives);",
        "end",
        "",
        "function check_parameters(block)",
        "  x0 = block.DialogPrm(1).Data;",
        f"  if ~isnumeric(x0) || ~isreal(x0) || numel(x0) ~= {2 * n}",
        f"    error('robodyn:sfun:x0', 'x0 must hold {2 * n} real values: q ({n}) then qd ({n})');",
        "  end",
        "end",
        "",
        "function initialize_conditions(block)",
        "  block.ContStates.Data = double(block.DialogPrm(1).Data(:));",
        "end",
        "",
        "function outputs(block)",
        "  x = block.ContStates.Data;",
        f"  block.OutputPort(1).Data = x(1:{n});",
        f"  block.OutputPort(2).Data = x({n + 1}:{2 * n});",
        "end",
        "",
        "function derivatives(block)",
        "  % xd = [qd; M(q)^-1 (tau - C(q, qd) qd - g(q) - friction)]",
        f"  block.Derivatives.Data = {stem}_mex('state_derivative', block.ContStates.Data, "
        "block.InputPort(1).Data(:));",
        "end",
        "",
    ])


def mex_files(kset: KernelSet, c_name: str | None = None, prefix: str | None = None) -> list[GeneratedFile]:
    """``<robot>_mex.c`` and, with a ``state_derivative`` kernel, ``<robot>_sfun.m``.

    Parameters
    ----------
    kset : KernelSet
    c_name : str, optional
        The C source to include (default ``<robot>.c``, as :func:`robodyn.codegen.c.c_files`
        names it).
    prefix : str, optional
        The prefix of the C functions in it (default ``<robot>_``).
    """
    stem = identifier(kset.robot_name)
    c_name = c_name or f"{kset.robot_name}.c"
    prefix = f"{stem}_" if prefix is None else prefix
    files = [GeneratedFile(f"{stem}_mex.c", mex_source(kset, c_name, prefix))]
    if "state_derivative" in kset.names:
        files.append(GeneratedFile(f"{stem}_sfun.m", sfunction_source(kset)))
    return files
