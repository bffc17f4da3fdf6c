/* A known client's service response in one foreign call: the request's id read from rclpy's
 * header, its client looked up among those answered before, rosidl's conversion of the Python
 * response under the GIL, rcl's send without it, the C message freed. Why the send goes without
 * the GIL: `acti_bringup.serving.unlocked`. The same through ctypes and Python took ~10 us of
 * the serving thread's CPU before the send in the node (five foreign calls, the header read
 * through two ctypes objects, the closures around them); rclpy's own send is one call.
 *
 * It knows no ROS type: `expect` tells it where rclpy keeps a header's C value (checked by
 * the caller against the header's sequence number), the caller passes rcl_send_response and
 * the message type's rosidl functions as addresses, and has checked the response's type. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdbool.h>

#define GUID_BYTES 16 /* rmw_request_id_t.writer_guid, its first field */

typedef int (*send_fn)(const void *entity, void *request_id, void *message);
typedef void *(*create_fn)(void);
typedef bool (*convert_fn)(PyObject *msg, void *message);
typedef void (*destroy_fn)(void *message);

static PyTypeObject *header_type;  /* rclpy's rmw_service_info_t */
static Py_ssize_t value_slot;      /* where its instance keeps the address of its C value */
static Py_ssize_t request_offset;  /* rmw_service_info_t.request_id */

static PyObject *expect(PyObject *module, PyObject *args)
{
    PyObject *type;
    if (!PyArg_ParseTuple(args, "O!nn", &PyType_Type, &type, &value_slot, &request_offset))
        return NULL;
    Py_XSETREF(header_type, (PyTypeObject *)Py_NewRef(type));
    Py_RETURN_NONE;
}

/* The C rmw_request_id_t behind a header of the expected type, else NULL. */
static char *request_of(PyObject *header)
{
    if (header_type == NULL || Py_TYPE(header) != header_type)
        return NULL;
    char *value = *(char **)((char *)header + value_slot);
    return value == NULL ? NULL : value + request_offset;
}

static PyObject *request_id(PyObject *module, PyObject *header)
{
    char *request = request_of(header);
    return request == NULL ? Py_NewRef(Py_None) : PyLong_FromVoidPtr(request);
}

static int address_at(PyObject *tuple, Py_ssize_t i, void **out)
{
    *out = PyLong_AsVoidPtr(PyTuple_GET_ITEM(tuple, i));
    return *out == NULL && PyErr_Occurred() ? -1 : 0;
}

enum { HEADER, ANSWERED, ENTITY, FUNCTIONS, MESSAGE, RESPONSE, ARGS };

static PyObject *respond(PyObject *module, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != ARGS || !PyAnySet_Check(args[ANSWERED]) || !PyTuple_Check(args[FUNCTIONS])
        || PyTuple_GET_SIZE(args[FUNCTIONS]) != 4) {
        PyErr_SetString(PyExc_TypeError, "respond(header, answered: set, entity, (send, create, "
                                         "convert, destroy), message, response)");
        return NULL;
    }
    char *request = request_of(args[HEADER]);
    if (request == NULL)
        Py_RETURN_NONE;
    PyObject *client = PyBytes_FromStringAndSize(request, GUID_BYTES);
    if (client == NULL)
        return NULL;
    int known = PySet_Contains(args[ANSWERED], client);
    Py_DECREF(client);
    if (known <= 0)
        return known < 0 ? NULL : Py_NewRef(Py_None);

    void *entity, *message, *send, *create, *convert, *destroy;
    if (address_at(args[FUNCTIONS], 0, &send) || address_at(args[FUNCTIONS], 1, &create)
        || address_at(args[FUNCTIONS], 2, &convert) || address_at(args[FUNCTIONS], 3, &destroy))
        return NULL;
    entity = PyLong_AsVoidPtr(args[ENTITY]);
    message = PyLong_AsVoidPtr(args[MESSAGE]);
    if (PyErr_Occurred())
        return NULL;
    void *converted = NULL; /* ours to free; a message passed in is the caller's */
    if (message == NULL) {
        converted = message = ((create_fn)create)();
        if (message == NULL)
            return PyErr_NoMemory();
        if (!((convert_fn)convert)(args[RESPONSE], message)) {
            ((destroy_fn)destroy)(message);
            if (!PyErr_Occurred())
                PyErr_SetString(PyExc_RuntimeError, "the response could not be converted");
            return NULL;
        }
    }
    int ret;
    Py_BEGIN_ALLOW_THREADS
    ret = ((send_fn)send)(entity, request, message);
    if (converted != NULL)
        ((destroy_fn)destroy)(converted);
    Py_END_ALLOW_THREADS
    return PyLong_FromLong(ret);
}

static PyMethodDef methods[] = {
    {"expect", expect, METH_VARARGS,
     "expect(header_type, value_slot, request_offset): where a header keeps its request's id."},
    {"request_id", request_id, METH_O,
     "request_id(header) -> the address of its C rmw_request_id_t as `expect` says, or None."},
    {"respond", (PyCFunction)(void (*)(void))respond, METH_FASTCALL,
     "respond(header, answered, entity, (send, create, convert, destroy), message, response) "
     "-> rcl's return code, or None (nothing sent) when the header is not of the expected type "
     "or its client's GUID is not in `answered`. `message`: the address of a C message to send "
     "as it is, or 0: then `response` is converted into a new one, freed after the send. The "
     "send (send(entity, request id, message)) runs with the GIL released."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_respond", "A known client's service response in one foreign call.",
    -1, methods,
};

PyMODINIT_FUNC PyInit__respond(void) { return PyModule_Create(&module); }
