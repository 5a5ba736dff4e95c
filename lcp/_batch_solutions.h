/* lcp.solve_many's Solutions built in C (included by lcp/_lemke_c.c after _lemke_solution.h,
 * whose `solution` and solve_setup's objects it uses). lcp/batch.py's `_lemke_batch` solves and
 * assesses k problems in one C loop (solve_batch with acc) and measures them all at once
 * (lcp_measure_batch); what was left per problem in Python -- the verdict, the basis, the
 * Solution -- is this loop:
 *
 *   batch_solutions(Z, W, basic, codes, pivots, acc, measured, tol, ferr_tol, equilibrated)
 *     -> a list of k entries: for problem p whose answer is accepted -- codes[p] = 0 (solved),
 *     acc[p, 0] = 0 (assessed in C), measured[p, :2] = (raw, scaled) with scaled <= tol,
 *     acc[p, 1] (berr) <= tol, acc[p, 2] (ferr) <= ferr_tol; a NaN fails each test -- the
 *     Solution `solved_lcp(z, w, "lemke", pivots[p], raw, scaled, basis, message, info, berr,
 *     ferr)` that _lemke_batch built, with z = Z[p] and w = W[p] (views of the rows, as there),
 *     basis the indices j of basic[p, j] != 0 (int64, ascending: np.flatnonzero(basic[p])),
 *     info {"equilibrated": equilibrated} (+ "polished": True when acc[p, 3] != 0); None for
 *     every other problem (the Python finishes it: numpy's judge or lcp.solve).
 *   Z, W: k x n float64; basic: k x n int8; codes, pivots: k int64; acc: k x 4 float64;
 *   measured: k x 4 float64 (_lemke_kernel.measure_batch's), all C-contiguous. */
#ifndef RIGIDLCP_BATCH_SOLUTIONS_H
#define RIGIDLCP_BATCH_SOLUTIONS_H

/* A new numpy array (numpy.empty) of n float64 (integer 0) or intp entries holding the n
 * 8-byte entries at src (the basis). */
static PyObject *array_of(idx n, int integer, const void *src)
{
    PyObject *arr = new_array(n, integer);
    if (!arr || !n) return arr;
    Py_buffer v;
    if (own_buffer(arr, &v, n * 8) < 0) {
        Py_DECREF(arr);
        return NULL;
    }
    memcpy(v.buf, src, (size_t)n * 8);
    PyBuffer_Release(&v);
    return arr;
}

static PyObject *py_batch_solutions(PyObject *self, PyObject *args)
{
    PyObject *oZ, *oW, *oB, *oc, *op, *oa, *om, *equilibrated;
    double tol, ferr_tol;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOOddO", &oZ, &oW, &oB, &oc, &op, &oa, &om, &tol,
                          &ferr_tol, &equilibrated))
        return NULL;
    if (!s_cls) {
        PyErr_SetString(PyExc_RuntimeError, "batch_solutions: solve_setup was not called");
        return NULL;
    }
    idx k = PyObject_Length(oc), n = 0;
    if (k < 0) return NULL;
    Py_buffer vZ = {0}, vW = {0}, vB = {0}, vc = {0}, vp = {0}, va = {0}, vm = {0};
    PyObject *list = NULL;
    if (get_buffer(oc, &vc, "codes", 'q', k, 0) < 0 || get_buffer(op, &vp, "pivots", 'q', k, 0) < 0
        || get_buffer(oa, &va, "acc", 'd', 4 * k, 0) < 0
        || get_buffer(om, &vm, "measured", 'd', 4 * k, 0) < 0)
        goto done;
    if (PyObject_GetBuffer(oZ, &vZ, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) goto done;
    n = vZ.ndim == 2 && vZ.shape[0] == k ? vZ.shape[1] : -1; /* Z: k x n */
    release(&vZ);
    if (n < 0) {
        PyErr_SetString(PyExc_ValueError, "batch_solutions: Z must be k x n");
        goto done;
    }
    if (get_buffer(oZ, &vZ, "Z", 'd', k * n, 0) < 0 || get_buffer(oW, &vW, "W", 'd', k * n, 0) < 0)
        goto done;
    if (PyObject_GetBuffer(oB, &vB, PyBUF_C_CONTIGUOUS) < 0) goto done;
    if (vB.len != k * n || vB.itemsize != 1) {
        PyErr_SetString(PyExc_ValueError, "basic: expected k n int8 values");
        goto done;
    }
    if (!(list = PyList_New(k))) goto done;
    const double *Z = (const double *)vZ.buf, *W = (const double *)vW.buf;
    const double *acc = (const double *)va.buf, *mea = (const double *)vm.buf;
    const int8_t *B = (const int8_t *)vB.buf;
    const int64_t *codes = (const int64_t *)vc.buf, *piv = (const int64_t *)vp.buf;
    int64_t bbuf[64], *basis = n <= 64 ? bbuf : (int64_t *)malloc((size_t)n * sizeof(int64_t));
    if (!basis) {
        PyErr_NoMemory();
        Py_CLEAR(list);
        goto done;
    }
    /* The collector off while the k Solutions are made (as it was): each one (and its info
     * dict) is a tracked container, and every 700 of them would start a collection that walks
     * the young ones again -- 0.08 us per problem at n = 10. The objects are the same; the
     * collector runs as usual at the next allocation after the loop. */
    int gc_was = PyGC_Disable();
    for (idx p = 0; p < k; p++) {
        const double *a = acc + 4 * p;
        double raw = mea[4 * p], scaled = mea[4 * p + 1];
        PyObject *sol = Py_None;
        if (codes[p] == 0 && a[0] == 0.0 && scaled <= tol && a[1] <= tol && a[2] <= ferr_tol) {
            idx nb = 0;
            for (idx j = 0; j < n; j++)
                if (B[p * n + j]) basis[nb++] = j;
            PyObject *z = PySequence_GetItem(oZ, p), *w = z ? PySequence_GetItem(oW, p) : NULL;
            PyObject *b = w ? array_of(nb, 1, basis) : NULL;
            sol = b ? solution(z, w, piv[p], raw, scaled, b, a[3] != 0.0, a[1], a[2],
                               equilibrated)
                    : NULL;
            Py_XDECREF(z);
            Py_XDECREF(w);
            Py_XDECREF(b);
            if (!sol) {
                Py_CLEAR(list);
                break;
            }
        } else {
            Py_INCREF(sol);
        }
        PyList_SET_ITEM(list, p, sol);
    }
    if (gc_was) PyGC_Enable();
    if (basis != bbuf) free(basis);
done:
    release(&vB);
    release(&vW);
    release(&vZ);
    release(&vm);
    release(&va);
    release(&vp);
    release(&vc);
    return list;
}

/* stack_lcps(problems, LCP) -> [(n, indices, Ms, qs), ...] or None: solve_many's grouping of
 * a list of lcp.LCPs by size, in C: for each size n, in the order of its first problem, the
 * list of the indices of the problems of that size and their M and q copied into new stacks
 * (numpy.empty((k, n, n)) and ((k, n))), as np.concatenate(...).reshape(...) stacks them. None
 * (the Python groups them itself, with its checks and messages) unless every entry is an
 * lcp.LCP (or a subclass) whose M is a C-contiguous native float64 n x n array and q a
 * native float64 vector of n entries. */
static PyObject *stack_array(PyObject *shape)
{
    return PyObject_Vectorcall(s_empty, &shape, 1, NULL);
}

static PyObject *py_stack_lcps(PyObject *self, PyObject *args)
{
    PyObject *list, *cls;
    (void)self;
    if (!PyArg_ParseTuple(args, "O!O!", &PyList_Type, &list, &PyType_Type, &cls)) return NULL;
    if (!s_empty) {
        PyErr_SetString(PyExc_RuntimeError, "stack_lcps: solve_setup was not called");
        return NULL;
    }
    static PyObject *key_M, *key_q;
    if (!key_M && (!(key_M = PyUnicode_InternFromString("M")) ||
                   !(key_q = PyUnicode_InternFromString("q"))))
        return NULL;
    idx k = PyList_GET_SIZE(list), groups = 0, held = 0;
    idx *ns = (idx *)malloc((size_t)(k + 1) * (2 * sizeof(idx) + 4 * sizeof(void *)));
    if (!ns) return PyErr_NoMemory();
    idx *sizes = ns + k + 1; /* the distinct sizes, in order */
    const double **data = (const double **)(sizes + k + 1);
    PyObject **refs = (PyObject **)(data + 2 * (k + 1)), *result = NULL;
    for (idx p = 0; p < k; p++) { /* each problem's n and data pointers; its M and q are held
                                   * to the end (an attribute may be made on the fly) */
        PyObject *obj = PyList_GET_ITEM(list, p);
        Py_buffer vM, vq;
        if (!PyObject_TypeCheck(obj, (PyTypeObject *)cls)) goto decline;
        if (!(refs[held] = PyObject_GetAttr(obj, key_M))) goto fail;
        held++;
        if (!(refs[held] = PyObject_GetAttr(obj, key_q))) goto fail;
        held++;
        idx n = plain_arrays(refs[held - 2], refs[held - 1], &vM, &vq, 0);
        if (n < 1) goto decline;
        data[2 * p] = (const double *)vM.buf, data[2 * p + 1] = (const double *)vq.buf;
        PyBuffer_Release(&vM);
        PyBuffer_Release(&vq);
        ns[p] = n;
        idx g = 0;
        while (g < groups && sizes[g] != n) g++;
        if (g == groups) sizes[groups++] = n;
    }
    if (!(result = PyList_New(groups))) goto fail;
    for (idx g = 0; g < groups; g++) {
        idx n = sizes[g], count = 0, j = 0;
        for (idx p = 0; p < k; p++) count += ns[p] == n;
        PyObject *indices = PyList_New(count), *Ms = NULL, *qs = NULL;
        PyObject *shape3 = Py_BuildValue("(nnn)", count, n, n), *shape2 = NULL;
        if (indices && shape3 && (shape2 = Py_BuildValue("(nn)", count, n)))
            if ((Ms = stack_array(shape3))) qs = stack_array(shape2);
        Py_XDECREF(shape3);
        Py_XDECREF(shape2);
        Py_buffer vMs = {0}, vqs = {0};
        int ok = qs && own_buffer(Ms, &vMs, count * n * n * 8) == 0 &&
                 own_buffer(qs, &vqs, count * n * 8) == 0;
        for (idx p = 0; ok && p < k; p++) {
            if (ns[p] != n) continue;
            PyObject *i = PyLong_FromSsize_t(p);
            if (!(ok = i != NULL)) break;
            PyList_SET_ITEM(indices, j, i);
            memcpy((double *)vMs.buf + j * n * n, data[2 * p], (size_t)(n * n) * 8);
            memcpy((double *)vqs.buf + j * n, data[2 * p + 1], (size_t)n * 8);
            j++;
        }
        release(&vMs);
        release(&vqs);
        PyObject *entry = ok ? Py_BuildValue("(nOOO)", n, indices, Ms, qs) : NULL;
        Py_XDECREF(indices);
        Py_XDECREF(Ms);
        Py_XDECREF(qs);
        if (!entry) goto fail;
        PyList_SET_ITEM(result, g, entry);
    }
    goto done;
decline:
    result = Py_NewRef(Py_None);
    goto done;
fail:
    Py_CLEAR(result);
done:
    while (held) Py_DECREF(refs[--held]);
    free(ns);
    return result;
}

#endif /* RIGIDLCP_BATCH_SOLUTIONS_H */
